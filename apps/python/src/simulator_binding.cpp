// simulator_binding.cpp: puncture.Simulator: the real-time model tick by
// tick, a whole scripted run as arrays, and the force meshes and layer
// surfaces as arrays for plotting.
#include <cmath>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "python_progress.hpp"
#include "run_result.hpp"
#include "scene_handle.hpp"
#include "simulator_handle.hpp"

namespace py = pybind11;

namespace puncture::python {

namespace {

/// One millimetre in metres: mm = metres / kMm as `puncture run` writes them, metres = mm * kMm.
constexpr double kMm = 1e-3;

std::size_t layer_of(const SimulatorHandle& s, const py::object& layer) {
  if (py::isinstance<py::str>(layer)) {
    try {
      return s.layer_index(layer.cast<std::string>());
    } catch (const std::out_of_range& e) {
      throw py::key_error(e.what());
    }
  }
  const long k = layer.cast<long>();
  if (k < 0 || k >= static_cast<long>(s.layer_names().size()))
    throw py::index_error("layer " + std::to_string(k) + " out of range (" + std::to_string(s.layer_names().size()) + " layers)");
  return static_cast<std::size_t>(k);
}

std::optional<double> mm_to_m(std::optional<double> mm) { return mm ? std::optional<double>(*mm * kMm) : std::nullopt; }

/// 3 x N positions (m) as an (N, 3) array in mm.
py::array_t<double> points_mm(const Eigen::Matrix3Xd& p) {
  py::array_t<double> a({static_cast<py::ssize_t>(p.cols()), py::ssize_t{3}});
  auto out = a.mutable_unchecked<2>();
  for (Eigen::Index i = 0; i < p.cols(); ++i)
    for (int c = 0; c < 3; ++c) out(i, c) = p(c, i) / kMm;
  return a;
}

/// The layer's fitted SH surface (the closed slab of the layer) on a polar x
/// azimuth grid of the parameter sphere: (n_polar, n_azimuth, 3) in mm.
py::array_t<double> layer_surface_mm(const SimulatorHandle& s, const py::object& layer, int n_polar, int n_azimuth) {
  if (n_polar < 2 || n_azimuth < 3) throw py::value_error("layer_surface_mm: n_polar >= 2 and n_azimuth >= 3");
  const LayerSurface& surface = *s.model().surfaces[layer_of(s, layer)];
  py::array_t<double> a({static_cast<py::ssize_t>(n_polar), static_cast<py::ssize_t>(n_azimuth), py::ssize_t{3}});
  auto out = a.mutable_unchecked<3>();
  for (int i = 0; i < n_polar; ++i) {
    const double theta = M_PI * i / (n_polar - 1);
    for (int j = 0; j < n_azimuth; ++j) {
      const double phi = 2.0 * M_PI * j / n_azimuth;
      const Eigen::Vector3d u(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
      const Eigen::Vector3d x = surface.position(u) / kMm;
      for (int c = 0; c < 3; ++c) out(i, j, c) = x(c);
    }
  }
  return a;
}

RunResult run(SimulatorHandle& s, const py::object& progress) {
  PythonCallback callback(progress);
  const ProgressCallback on_progress = [&callback](double fraction) { callback(fraction); };
  ScriptedRunResult result;
  try {
    py::gil_scoped_release release;
    result = s.run(on_progress);
  } catch (const CallbackAborted&) {
    s.reset();  // the tissue is where the interrupted run left it
    callback.rethrow_if_raised();
    throw;
  }
  return make_run_result(s.scene(), result);
}

py::list events(const SimulatorHandle& s) {
  py::list l;
  for (const PunctureEvent& e : s.simulator().puncture_events()) l.append(py::cast(EventRecord(e)));
  return l;
}

void bind_plotting(py::class_<SimulatorHandle>& c) {
  c.def(
       "force_mesh_nodes_mm",
       [](const SimulatorHandle& s, const py::object& layer, bool rest) {
         const std::size_t k = layer_of(s, layer);
         return points_mm(rest ? s.simulator().node_rest_positions(k) : s.simulator().node_positions(k));
       },
       py::arg("layer"), py::arg("rest") = false,
       "The layer's force-mesh nodes (N, 3) in mm, scene frame: where they are now (the mesh while intact, the "
       "resumption after the break, as drawn), or at rest. Empty (0, 3) without force meshes.")
      .def(
          "force_mesh_rings",
          [](const SimulatorHandle& s, const py::object& layer) {
            const std::vector<int>& rings = s.simulator().node_rings(layer_of(s, layer));
            return py::array_t<int>(static_cast<py::ssize_t>(rings.size()), rings.data());
          },
          py::arg("layer"), "1-based ring index of every force-mesh node (int array, same order as force_mesh_nodes_mm).")
      .def("layer_surface_mm", &layer_surface_mm, py::arg("layer"), py::arg("n_polar") = 33, py::arg("n_azimuth") = 64,
           "The layer's SH surface (rest shape: top face, rim, bottom face) on a grid of the parameter sphere, "
           "(n_polar, n_azimuth, 3) in mm, e.g. for matplotlib's plot_surface.");
}

}  // namespace

void bind_simulator(py::module_& m) {
  py::class_<SimulatorHandle> c(m, "Simulator",
                                "The real-time model of a scene (core/include/puncture/simulator.hpp): SH layer "
                                "surfaces, force meshes and the force law, one haptic tick at a time.");
  c.def(py::init([](const SceneHandle& scene) { return std::make_unique<SimulatorHandle>(scene.scene); }), py::arg("scene"))
      .def(
          "tick",
          [](SimulatorHandle& s, double depth_mm, std::optional<double> velocity_mm_per_s, std::optional<double> time_s) {
            return s.tick_depth(depth_mm * kMm, mm_to_m(velocity_mm_per_s), time_s);
          },
          py::arg("depth_mm"), py::arg("velocity_mm_per_s") = py::none(), py::arg("time_s") = py::none(),
          "One haptic tick, the tip on the scene's insertion line (through the origin at insertion.angle_deg to the "
          "surface normal) at depth_mm below the undeformed skin. Defaults: time_s = the last tick's + time_step_s "
          "(0 first), velocity along the needle from the depth change over time_step_s (0 first). Returns a Tick (force and its parts, layers, this tick's punctures).")
      .def(
          "tick_pose",
          [](SimulatorHandle& s, const Eigen::Vector3d& tip_mm, const Eigen::Vector3d& direction, double velocity_mm_per_s,
             std::optional<double> time_s) { return s.tick_pose(tip_mm * kMm, direction, velocity_mm_per_s * kMm, time_s); },
          py::arg("tip_position_mm"), py::arg("direction"), py::arg("velocity_mm_per_s"), py::arg("time_s") = py::none(),
          "One haptic tick with the needle's pose: tip position (mm, scene frame, skin surface at z = 0, tissue below), "
          "unit insertion direction, speed along it (> 0 inserting).")
      .def("run", &run, py::arg("progress") = py::none(),
           "The scene's scripted insertion (approach, insertion, dwell, withdrawal) from fresh tissue, as `puncture run` "
           "does it: a RunResult of NumPy arrays. progress(fraction) is called about every 10 %; Ctrl-C interrupts.")
      .def("reset", &SimulatorHandle::reset, "Fresh tissue (the model rebuilt from the scene).")
      .def_property_readonly("scene", [](const SimulatorHandle& s) { return SceneHandle{s.scene(), s.scene().source_path}; })
      .def_property_readonly("time_step_s", &SimulatorHandle::time_step_s, "1 / haptic_rate_Hz")
      .def_property_readonly("ticks", &SimulatorHandle::ticks, "ticks since the tissue was fresh")
      .def_property_readonly("layer_names", &SimulatorHandle::layer_names)
      .def_property_readonly("layer_states",
                             [](const SimulatorHandle& s) {
                               py::dict d;
                               for (std::size_t k = 0; k < s.layer_names().size(); ++k)
                                 d[py::str(s.layer_names()[k])] = to_string(s.simulator().layer_state(k));
                               return d;
                             })
      .def_property_readonly("events", &events, "every puncture so far")
      .def_property_readonly("mesh_energy_J", [](const SimulatorHandle& s) { return s.simulator().mesh_energy_J(); });
  bind_plotting(c);
}

}  // namespace puncture::python
