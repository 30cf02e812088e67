// run_result.cpp: puncture.RunResult (run_result.hpp).
//
// Arrays, one row per haptic tick (n ticks, L layers):
//   time_s, depth_mm, velocity_mm_per_s, force_N, tip_force_N,
//   surface_force_N, cutting_force_N, friction_force_N,
//   path_depth_mm, lateral_force_N                            (n,) float64
//   force_vector_N, torque_about_entry_N_m                    (n, 3) float64, scene frame
//   phase                                                     (n,) int8: phase_names
//   layer_state                                               (n, L) int8: state_names
//   layer_surface_force_N, layer_support_force_N, layer_cutting_force_N,
//   layer_friction_force_N, layer_damping_force_N,
//   layer_contact_deflection_mm, layer_shaft_length_mm       (n, L) float64
//   layer_deformed_rings                                      (n, L) int32
//   tick_wall_time_s                                          (n,) float64: tick() measured inside the run
#include "run_result.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "puncture/needle.hpp"
#include "tick_types.hpp"

namespace py = pybind11;

namespace puncture::python {

namespace {

/// One millimetre in metres: values in mm are metres / kMm, as `puncture run` writes them.
constexpr double kMm = 1e-3;

template <class T, class Value>
py::array_t<T> tick_column(const std::vector<TickResult>& ticks, Value value) {
  py::array_t<T> a(static_cast<py::ssize_t>(ticks.size()));
  auto out = a.template mutable_unchecked<1>();
  for (std::size_t i = 0; i < ticks.size(); ++i) out(static_cast<py::ssize_t>(i)) = static_cast<T>(value(ticks[i]));
  return a;
}

template <class T, class Value>
py::array_t<T> layer_column(const std::vector<TickResult>& ticks, std::size_t layers, Value value) {
  py::array_t<T> a({static_cast<py::ssize_t>(ticks.size()), static_cast<py::ssize_t>(layers)});
  auto out = a.template mutable_unchecked<2>();
  for (std::size_t i = 0; i < ticks.size(); ++i)
    for (std::size_t k = 0; k < layers; ++k)
      out(static_cast<py::ssize_t>(i), static_cast<py::ssize_t>(k)) = static_cast<T>(value(ticks[i].layers[k]));
  return a;
}

/// (ticks, 3) array of a per-tick vector.
template <class Value>
py::array_t<double> vector_column(const std::vector<TickResult>& ticks, Value value) {
  py::array_t<double> a({static_cast<py::ssize_t>(ticks.size()), py::ssize_t{3}});
  auto out = a.mutable_unchecked<2>();
  for (std::size_t i = 0; i < ticks.size(); ++i) {
    const Eigen::Vector3d v = value(ticks[i]);
    for (py::ssize_t c = 0; c < 3; ++c) out(static_cast<py::ssize_t>(i), c) = v[c];
  }
  return a;
}

void add_needle_columns(py::dict& a, const Scene& scene, const std::vector<TickResult>& ticks) {
  a["time_s"] = tick_column<double>(ticks, [](const TickResult& t) { return t.time_s; });
  a["depth_mm"] = tick_column<double>(ticks, [](const TickResult& t) { return t.depth_m / kMm; });
  a["velocity_mm_per_s"] = tick_column<double>(ticks, [](const TickResult& t) { return t.velocity_m_per_s / kMm; });
  a["force_N"] = tick_column<double>(ticks, [](const TickResult& t) { return t.total_force_N; });
  a["tip_force_N"] = tick_column<double>(ticks, [](const TickResult& t) { return t.tip_force_N; });
  a["surface_force_N"] = tick_column<double>(ticks, [](const TickResult& t) { return t.surface_force_N; });
  a["cutting_force_N"] = tick_column<double>(ticks, [](const TickResult& t) { return t.cutting_force_N; });
  a["friction_force_N"] = tick_column<double>(ticks, [](const TickResult& t) { return t.friction_force_N; });
  a["path_depth_mm"] = tick_column<double>(ticks, [](const TickResult& t) { return t.path_depth_m / kMm; });
  a["lateral_force_N"] = tick_column<double>(ticks, [](const TickResult& t) { return t.lateral_force_N; });
  a["force_vector_N"] = vector_column(ticks, [](const TickResult& t) { return t.force_on_needle_N; });
  a["torque_about_entry_N_m"] = vector_column(ticks, [](const TickResult& t) { return t.torque_about_entry_N_m; });
  const ScriptedTrajectory trajectory(scene.insertion);
  // The phase as `puncture run` writes it (run_command.cpp curve_csv).
  a["phase"] = tick_column<std::int8_t>(ticks, [&](const TickResult& t) {
    return t.time_s < trajectory.insertion_end_s() ? 0 : t.time_s < trajectory.withdrawal_start_s() ? 1 : 2;
  });
}

void add_layer_columns(py::dict& a, const std::vector<TickResult>& ticks, std::size_t n) {
  a["layer_state"] = layer_column<std::int8_t>(ticks, n, [](const LayerTickResult& l) { return static_cast<int>(l.state); });
  a["layer_surface_force_N"] = layer_column<double>(ticks, n, [](const LayerTickResult& l) { return l.surface_force_N; });
  a["layer_support_force_N"] = layer_column<double>(ticks, n, [](const LayerTickResult& l) { return l.support_force_N; });
  a["layer_cutting_force_N"] = layer_column<double>(ticks, n, [](const LayerTickResult& l) { return l.cutting_force_N; });
  a["layer_friction_force_N"] = layer_column<double>(ticks, n, [](const LayerTickResult& l) { return l.friction_force_N; });
  a["layer_damping_force_N"] = layer_column<double>(ticks, n, [](const LayerTickResult& l) { return l.damping_force_N; });
  a["layer_deformed_rings"] = layer_column<std::int32_t>(ticks, n, [](const LayerTickResult& l) { return l.deformed_rings; });
  a["layer_contact_deflection_mm"] =
      layer_column<double>(ticks, n, [](const LayerTickResult& l) { return l.contact_deflection_m / kMm; });
  a["layer_shaft_length_mm"] = layer_column<double>(ticks, n, [](const LayerTickResult& l) { return l.shaft_length_m / kMm; });
}

py::object attribute(const RunResult& r, const std::string& name) {
  if (r.arrays.contains(name)) return r.arrays[py::str(name)];
  throw py::attribute_error("RunResult has no array '" + name + "' (keys(): " +
                            py::str(py::list(r.arrays.attr("keys")())).cast<std::string>() + ")");
}

std::size_t layer_index(const RunResult& r, const py::object& layer) {
  if (py::isinstance<py::str>(layer)) {
    const std::string name = layer.cast<std::string>();
    for (std::size_t k = 0; k < r.layer_names.size(); ++k)
      if (r.layer_names[k] == name) return k;
    throw py::key_error("no layer '" + name + "' in this run");
  }
  const long k = layer.cast<long>();
  if (k < 0 || k >= static_cast<long>(r.layer_names.size())) throw py::index_error("layer index out of range");
  return static_cast<std::size_t>(k);
}

/// The index [:, k] of a (ticks, layers) array.
py::tuple layer_column_index(std::size_t k) {
  return py::make_tuple(py::module_::import("builtins").attr("slice")(py::none()), k);
}

/// The layer's columns (views into the (n, L) arrays), named without the "layer_" prefix.
py::dict layer_view(const RunResult& r, const py::object& layer) {
  const std::size_t k = layer_index(r, layer);
  py::dict d;
  for (const auto& [key, value] : r.arrays) {
    const std::string name = key.cast<std::string>();
    if (name.rfind("layer_", 0) == 0) d[py::str(name.substr(6))] = value[layer_column_index(k)];
  }
  return d;
}

/// The run in the schema of `puncture run`'s realtime_curve.csv (what
/// calibrate() takes as a reference): {column: array}, states and phase as text.
py::dict curve_columns(const RunResult& r) {
  py::module_ numpy = py::module_::import("numpy");
  py::dict d;
  for (const char* name : {"time_s", "depth_mm", "velocity_mm_per_s", "force_N", "tip_force_N", "cutting_force_N",
                           "friction_force_N"})
    d[name] = r.arrays[name];
  d["phase"] = numpy.attr("asarray")(phase_names())[r.arrays["phase"]];
  d["path_depth_mm"] = r.arrays["path_depth_mm"];
  d["lateral_force_N"] = r.arrays["lateral_force_N"];
  const py::ssize_t rows = py::len(r.arrays["time_s"]);
  const std::string axes = "xyz";
  for (py::ssize_t c = 0; c < 3; ++c) {
    const py::tuple column = py::make_tuple(py::slice(0, rows, 1), c);
    d[py::str(std::string("force_") + axes[c] + "_N")] = r.arrays["force_vector_N"][column];
    d[py::str(std::string("torque_") + axes[c] + "_N_m")] = r.arrays["torque_about_entry_N_m"][column];
  }
  const py::object states = numpy.attr("asarray")(state_names());
  for (std::size_t k = 0; k < r.layer_names.size(); ++k) {
    const py::tuple column = layer_column_index(k);
    d[py::str(r.layer_names[k] + "_state")] = states[r.arrays["layer_state"][column]];
    for (const char* part : {"surface_force_N", "cutting_force_N", "friction_force_N", "damping_force_N"})
      d[py::str(r.layer_names[k] + "_" + part)] = r.arrays[py::str(std::string("layer_") + part)][column];
  }
  return d;
}

}  // namespace

const std::vector<std::string>& phase_names() {
  static const std::vector<std::string> names{"insertion", "dwell", "withdrawal"};
  return names;
}
const std::vector<std::string>& state_names() {
  static const std::vector<std::string> names{to_string(LayerState::Untouched), to_string(LayerState::Pressed),
                                              to_string(LayerState::Punctured)};
  return names;
}

RunResult make_run_result(const Scene& scene, const ScriptedRunResult& run) {
  RunResult r;
  r.time_step_s = run.time_step_s;
  for (const Layer& l : scene.layers) r.layer_names.push_back(l.name);
  add_needle_columns(r.arrays, scene, run.ticks);
  add_layer_columns(r.arrays, run.ticks, scene.layers.size());
  py::array_t<double> wall(static_cast<py::ssize_t>(run.tick_wall_time_s.size()), run.tick_wall_time_s.data());
  r.arrays["tick_wall_time_s"] = wall;
  for (const PunctureEvent& e : run.events) r.events.append(py::cast(EventRecord(e)));
  return r;
}

void bind_run_result(py::module_& m) {
  py::class_<RunResult>(m, "RunResult",
                        "A scripted insertion, one row per haptic tick: NumPy arrays by name (result.force_N, "
                        "result['depth_mm'], keys()); per-layer arrays are (ticks, layers), layer columns in "
                        "layer_names order; layer(name) gives one layer's columns.")
      .def("__getattr__", &attribute)
      .def("__getitem__", &attribute)
      .def("__contains__", [](const RunResult& r, const std::string& k) { return r.arrays.contains(k); })
      .def("keys", [](const RunResult& r) { return r.arrays.attr("keys")(); })
      .def("arrays", [](const RunResult& r) { return py::dict(r.arrays); }, "name -> array (a new dict of the same arrays)")
      .def("layer", &layer_view, py::arg("layer"), "One layer's columns by name or index (views).")
      .def("curve", &curve_columns,
           "The run as {column: array} in the schema of `puncture run`'s realtime_curve.csv (phase and states as "
           "text): a reference curve for calibrate().")
      .def("__dir__", [](const RunResult& r) {
        py::list names = py::list(r.arrays.attr("keys")());
        for (const char* extra : {"events", "layer_names", "time_step_s", "state_names", "phase_names", "layer", "curve", "keys", "arrays"})
          names.append(extra);
        return names;
      })
      .def("__len__", [](const RunResult& r) { return py::len(r.arrays["time_s"]); })
      .def("__repr__",
           [](const RunResult& r) {
             std::string layers;
             for (const std::string& l : r.layer_names) layers += (layers.empty() ? "" : ", ") + l;
             return "<puncture.RunResult " + std::to_string(py::len(r.arrays["time_s"])) + " ticks of " +
                    std::to_string(r.time_step_s) + " s; layers " + layers + "; " + std::to_string(py::len(r.events)) +
                    " punctures>";
           })
      .def_readonly("events", &RunResult::events)
      .def_readonly("layer_names", &RunResult::layer_names)
      .def_readonly("time_step_s", &RunResult::time_step_s)
      .def_property_readonly("state_names", [](const RunResult&) { return state_names(); },
                             "layer_state code -> name (the CSV's state column)")
      .def_property_readonly("phase_names", [](const RunResult&) { return phase_names(); });
}

}  // namespace puncture::python
