// realtime_view.hpp: the VTK view of puncture-app (runs on the main thread).
//
// Shows the slab cut open along y = 0 (layer_view_geometry.hpp): the three
// layer surfaces at the scene's SH degree, deformed by their force meshes,
// the force-mesh nodes, the needle, a dark ring where a layer is punctured,
// a text overlay (time, depth, forces, per-layer state, live loop numbers,
// guard and stability warnings) and a live force-depth graph (VTK chart) of
// the current insertion. It reads only what the haptic thread publishes (a
// ViewSnapshot through a triple buffer, TickSamples through a ring): it never
// touches the model.
// Interaction (interactive mode, with the mouse device):
//   mouse wheel            needle up / down 0.25 mm (Shift: 0.05 mm)
//   Shift + left drag      needle depth (vertical) and x (horizontal), 0.05 mm per pixel
//   arrow keys Up / Down   needle up / down 0.5 mm;  Left / Right: x -/+ 1 mm
//   Page Up / Page Down    y +/- 1 mm;  Home: needle back to its start
//   n                      fresh tissue (once the needle is above the skin)
//   c                      reset the camera;  q or Esc: quit
//   left drag / right drag / middle drag: rotate / zoom / pan the camera
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "puncture/model/realtime_model.hpp"
#include "puncture/realtime/pointer_device.hpp"
#include "puncture/realtime/view_snapshot.hpp"

class vtkRenderWindowInteractor;

namespace puncture::realtime {

struct ViewOptions {
  bool offscreen = false;
  int width = 1280, height = 800;
  std::string title = "puncture-app";
  double graph_max_force_N = 3.0;  ///< initial force range of the graph (it grows when exceeded)
};

/// Live numbers shown in the overlay, filled by the caller each frame.
struct ViewStatus {
  std::string scene_name, device_name;
  double haptic_rate_Hz = 0.0;
  double view_fps = 0.0;
  std::int64_t missed_deadlines = 0;
  std::vector<std::string> warnings;  ///< stability warnings (shown shortened)
  std::string note;                   ///< e.g. replay progress
};

class RealtimeView {
 public:
  /// Builds the scene graph from the model's surfaces and force-mesh lattices
  /// (read once here, before the haptic thread starts). `pointer` may be null.
  RealtimeView(const Scene& scene, const RealtimeModel& model, ViewOptions options, PointerDevice* pointer);
  ~RealtimeView();

  /// Adds samples of the current insertion to the graph history.
  void add_sample(const TickSample& sample);
  /// Updates every actor from the snapshot and renders one frame (the
  /// overlay text every fourth frame, or now if `force_text`). The graph shows
  /// the samples up to `graph_until_s` (needle time; default: all).
  void render(const ViewSnapshot& snapshot, const ViewStatus& status, bool force_text = false,
              double graph_until_s = 1e300);
  /// Writes the last rendered frame as PNG (staged under a temporary name, then renamed).
  void screenshot(const std::string& png_path);

  /// Interactive mode: calls `on_frame` every `period_ms` from the event loop until it returns false or the window closes.
  void run_interactive(int period_ms, const std::function<bool()>& on_frame);
  /// The window's interactor (nullptr offscreen); tests send it key and mouse events.
  vtkRenderWindowInteractor* interactor();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace puncture::realtime
