// force_depth_graph.hpp: the live force-depth graph of the view, drawn with
// plain 2D actors (a frame, grid lines, static tick labels, two polylines:
// the model force and the force sent to the device). Cheaper to render every
// frame than a VTK chart; the axis ranges grow (and the labels are rebuilt)
// only when a sample falls outside them.
#pragma once

#include <deque>
#include <vector>

#include <vtkActor2D.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkTextActor.h>

#include "puncture/realtime/view_snapshot.hpp"

namespace puncture::realtime {

class ForceDepthGraph {
 public:
  /// Viewport-normalised box (x0, y0) - (x1, y1); initial ranges in mm and N.
  void build(vtkRenderer* renderer, double x0, double y0, double x1, double y1, double max_depth_mm,
             double max_force_N);
  /// Draws the samples with time_s <= until_s.
  void update(const std::deque<TickSample>& history, double until_s = 1e300);
  void hide();

 private:
  void rebuild_axes();
  double to_x(double depth_mm) const { return x0_ + (x1_ - x0_) * (depth_mm - d0_) / (d1_ - d0_); }
  double to_y(double force_N) const { return y0_ + (y1_ - y0_) * (force_N - f0_) / (f1_ - f0_); }

  vtkRenderer* renderer_ = nullptr;
  double x0_ = 0, y0_ = 0, x1_ = 1, y1_ = 1;
  double d0_ = -2, d1_ = 30, f0_ = -0.25, f1_ = 3;
  vtkSmartPointer<vtkActor2D> background_, grid_, model_line_, sent_line_, lateral_line_;
  vtkSmartPointer<vtkPolyData> grid_data_, model_data_, sent_data_, lateral_data_;
  std::vector<vtkSmartPointer<vtkTextActor>> labels_, titles_;
  bool hidden_ = false;
};

}  // namespace puncture::realtime
