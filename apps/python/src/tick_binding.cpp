// tick_binding.cpp: puncture.Tick, puncture.LayerTick, puncture.PunctureEvent
// (read-only views of one haptic tick; mm where the name says so).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "tick_types.hpp"

namespace py = pybind11;

namespace puncture::python {

namespace {

/// One millimetre in metres: values in mm are metres / kMm, as `puncture run` writes them.
constexpr double kMm = 1e-3;

void bind_event(py::module_& m) {
  py::class_<EventRecord>(m, "PunctureEvent", "A layer giving way under the needle (core/include/puncture/puncture_force.hpp).")
      .def_property_readonly("layer", [](const EventRecord& e) { return e.event.layer; }, "index, 0 = top layer")
      .def_property_readonly("layer_name", [](const EventRecord& e) { return e.layer_name; })
      .def_property_readonly("time_s", [](const EventRecord& e) { return e.event.time_s; })
      .def_property_readonly("depth_mm", [](const EventRecord& e) { return e.event.depth_m / kMm; })
      .def_property_readonly("surface_force_N", [](const EventRecord& e) { return e.event.surface_force_N; })
      .def_property_readonly("total_force_N", [](const EventRecord& e) { return e.event.total_force_N; },
                             "needle force just before the surface gave way")
      .def_property_readonly("cutting_force_N", [](const EventRecord& e) { return e.event.cutting_force_N; })
      .def_property_readonly("eq5_force_N", [](const EventRecord& e) { return e.event.eq5_force_N; })
      .def_property_readonly("mesh_reaction_N", [](const EventRecord& e) { return e.event.mesh_reaction_N; })
      .def_property_readonly("tip_stiffening_force_N", [](const EventRecord& e) { return e.event.tip_stiffening_force_N; })
      .def("to_dict",
           [](const EventRecord& e) {
             return py::dict(py::arg("layer") = e.layer_name, py::arg("time_s") = e.event.time_s,
                             py::arg("depth_mm") = e.event.depth_m / kMm,
                             py::arg("surface_force_N") = e.event.surface_force_N,
                             py::arg("total_force_N") = e.event.total_force_N);
           })
      .def("__repr__", [](const EventRecord& e) {
        return "<puncture.PunctureEvent " + e.layer_name + " at " + std::to_string(e.event.depth_m / kMm) +
               " mm, " + std::to_string(e.event.total_force_N) + " N>";
      });
}

void bind_layer_tick(py::module_& m) {
  py::class_<LayerTickResult>(m, "LayerTick", "One layer in one tick (simulator.hpp LayerTickResult).")
      .def_property_readonly("state", [](const LayerTickResult& l) { return to_string(l.state); },
                             "'untouched', 'pressed' or 'punctured'")
      .def_readonly("surface_force_N", &LayerTickResult::surface_force_N)
      .def_readonly("support_force_N", &LayerTickResult::support_force_N)
      .def_readonly("cutting_force_N", &LayerTickResult::cutting_force_N)
      .def_readonly("friction_force_N", &LayerTickResult::friction_force_N)
      .def_readonly("damping_force_N", &LayerTickResult::damping_force_N)
      .def_readonly("deformed_rings", &LayerTickResult::deformed_rings)
      .def_readonly("stored_energy_J", &LayerTickResult::stored_energy_J)
      .def_property_readonly("contact_deflection_mm", [](const LayerTickResult& l) { return l.contact_deflection_m / kMm; })
      .def_property_readonly("shaft_length_mm", [](const LayerTickResult& l) { return l.shaft_length_m / kMm; });
}

}  // namespace

void bind_tick(py::module_& m) {
  bind_event(m);
  bind_layer_tick(m);
  py::class_<TickRecord>(m, "Tick",
                         "One haptic tick: the needle force (N, > 0 resisting insertion) and its parts, the layers, "
                         "the punctures of this tick.")
      .def_property_readonly("time_s", [](const TickRecord& t) { return t.result.time_s; })
      .def_property_readonly("depth_mm", [](const TickRecord& t) { return t.result.depth_m / kMm; })
      .def_property_readonly("velocity_mm_per_s", [](const TickRecord& t) { return t.result.velocity_m_per_s / kMm; })
      .def_property_readonly("force_N", [](const TickRecord& t) { return t.result.total_force_N; },
                             "needle force along the axis: tip + cutting + friction")
      .def_property_readonly("tip_force_N", [](const TickRecord& t) { return t.result.tip_force_N; })
      .def_property_readonly("surface_force_N", [](const TickRecord& t) { return t.result.surface_force_N; })
      .def_property_readonly("cutting_force_N", [](const TickRecord& t) { return t.result.cutting_force_N; })
      .def_property_readonly("friction_force_N", [](const TickRecord& t) { return t.result.friction_force_N; })
      .def_property_readonly("force_vector_N", [](const TickRecord& t) { return t.result.force_on_needle_N; },
                             "the tissue's whole force on the needle (N, scene frame): along the axis against the "
                             "insertion, plus the part across it of a needle inclined to the surface normal")
      .def_property_readonly("lateral_force_N", [](const TickRecord& t) { return t.result.lateral_force_N; },
                             "|force across the needle axis| (N; 0 along the surface normal)")
      .def_property_readonly("torque_about_entry_N_m", [](const TickRecord& t) { return t.result.torque_about_entry_N_m; },
                             "moment of force_vector_N about the entry point (the axis' crossing with z = 0), N m")
      .def_property_readonly("path_depth_mm", [](const TickRecord& t) { return t.result.path_depth_m / kMm; },
                             "tip past the entry point along the needle (mm): depth_mm / cos(angle to the vertical)")
      .def_property_readonly("layers", [](const TickRecord& t) { return t.result.layers; })
      .def_property_readonly("layer_states",
                             [](const TickRecord& t) {
                               py::dict d;
                               for (std::size_t k = 0; k < t.result.layers.size(); ++k)
                                 d[py::str((*t.layer_names)[k])] = to_string(t.result.layers[k].state);
                               return d;
                             },
                             "{layer name: 'untouched' | 'pressed' | 'punctured'}")
      .def_property_readonly("events", [](const TickRecord& t) { return t.events; }, "punctures in this tick")
      .def("__repr__", [](const TickRecord& t) {
        return "<puncture.Tick t=" + std::to_string(t.result.time_s) + " s depth=" +
               std::to_string(t.result.depth_m / kMm) + " mm force=" + std::to_string(t.result.total_force_N) + " N>";
      });
}

}  // namespace puncture::python
