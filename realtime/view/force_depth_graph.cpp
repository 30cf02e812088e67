#include "force_depth_graph.hpp"

#include <vtkCellArray.h>
#include <vtkCoordinate.h>
#include <vtkNew.h>
#include <vtkPolyDataMapper2D.h>
#include <vtkProperty2D.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace puncture::realtime {
namespace {

constexpr double kMm = 1e-3;

vtkSmartPointer<vtkActor2D> make_actor(vtkPolyData* data, double r, double g, double b, double width) {
  vtkNew<vtkCoordinate> normalized;
  normalized->SetCoordinateSystemToNormalizedViewport();
  vtkNew<vtkPolyDataMapper2D> mapper;
  mapper->SetInputData(data);
  mapper->SetTransformCoordinate(normalized);
  auto actor = vtkSmartPointer<vtkActor2D>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(r, g, b);
  actor->GetProperty()->SetLineWidth(width);
  return actor;
}

/// A "nice" tick step (1, 2 or 5 times a power of ten) giving about `n` ticks over `range`.
double tick_step(double range, int n) {
  const double raw = range / n;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= raw) return m * p;
  return 10.0 * p;
}

}  // namespace

void ForceDepthGraph::build(vtkRenderer* renderer, double x0, double y0, double x1, double y1, double max_depth_mm,
                            double max_force_N) {
  renderer_ = renderer;
  // Leave room for the labels inside the box.
  x0_ = x0 + 0.045;
  y0_ = y0 + 0.06;
  x1_ = x1 - 0.01;
  y1_ = y1 - 0.05;
  d0_ = -2.0;
  d1_ = max_depth_mm * 1.05;
  f0_ = -0.05 * max_force_N;
  f1_ = max_force_N;

  // Background panel.
  vtkNew<vtkPolyData> panel;
  vtkNew<vtkPoints> pp;
  pp->InsertNextPoint(x0, y0, 0);
  pp->InsertNextPoint(x1, y0, 0);
  pp->InsertNextPoint(x1, y1, 0);
  pp->InsertNextPoint(x0, y1, 0);
  vtkNew<vtkCellArray> quad;
  const vtkIdType ids[4] = {0, 1, 2, 3};
  quad->InsertNextCell(4, ids);
  panel->SetPoints(pp);
  panel->SetPolys(quad);
  background_ = make_actor(panel, 1.0, 1.0, 1.0, 1.0);
  background_->GetProperty()->SetOpacity(0.85);
  renderer->AddActor2D(background_);

  grid_data_ = vtkSmartPointer<vtkPolyData>::New();
  grid_ = make_actor(grid_data_, 0.6, 0.6, 0.6, 1.0);
  renderer->AddActor2D(grid_);

  for (vtkSmartPointer<vtkPolyData>* data : {&model_data_, &sent_data_, &lateral_data_}) {
    *data = vtkSmartPointer<vtkPolyData>::New();
    (*data)->SetPoints(vtkSmartPointer<vtkPoints>::New());
    (*data)->SetLines(vtkSmartPointer<vtkCellArray>::New());
  }
  sent_line_ = make_actor(sent_data_, 0.15, 0.35, 0.85, 3.0);
  model_line_ = make_actor(model_data_, 0.80, 0.10, 0.10, 1.5);
  lateral_line_ = make_actor(lateral_data_, 0.10, 0.55, 0.20, 1.5);
  renderer->AddActor2D(sent_line_);
  renderer->AddActor2D(model_line_);
  renderer->AddActor2D(lateral_line_);

  // Legend and axis titles (static).
  auto text = [&](const char* s, double x, double y, double r, double g, double b, int size, bool right = false) {
    auto t = vtkSmartPointer<vtkTextActor>::New();
    t->SetInput(s);
    t->GetTextProperty()->SetFontSize(size);
    t->GetTextProperty()->SetColor(r, g, b);
    if (right) t->GetTextProperty()->SetJustificationToRight();
    t->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    t->GetPositionCoordinate()->SetValue(x, y);
    renderer->AddActor2D(t);
    titles_.push_back(t);
  };
  text("tissue force (N)", x0_ + 0.01, y1_ + 0.012, 0.8, 0.1, 0.1, 14);
  text("force to device (N)", x0_ + 0.13, y1_ + 0.012, 0.15, 0.35, 0.85, 14);
  text("across (N)", x0_ + 0.265, y1_ + 0.012, 0.10, 0.55, 0.20, 14);
  text("depth (mm)", x1_, y0 + 0.005, 0.2, 0.2, 0.2, 13, true);
  rebuild_axes();
}

void ForceDepthGraph::rebuild_axes() {
  for (auto& l : labels_) renderer_->RemoveActor2D(l);
  labels_.clear();
  vtkNew<vtkPoints> pts;
  vtkNew<vtkCellArray> lines;
  auto line = [&](double xa, double ya, double xb, double yb) {
    const vtkIdType a = pts->InsertNextPoint(xa, ya, 0), b = pts->InsertNextPoint(xb, yb, 0);
    const vtkIdType ids[2] = {a, b};
    lines->InsertNextCell(2, ids);
  };
  auto label = [&](double value, double x, double y, bool right) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", std::abs(value) < 1e-9 ? 0.0 : value);
    auto t = vtkSmartPointer<vtkTextActor>::New();
    t->SetInput(buf);
    t->GetTextProperty()->SetFontSize(12);
    t->GetTextProperty()->SetColor(0.2, 0.2, 0.2);
    if (right) t->GetTextProperty()->SetJustificationToRight();
    t->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    t->GetPositionCoordinate()->SetValue(x, y);
    renderer_->AddActor2D(t);
    labels_.push_back(t);
  };
  const double ds = tick_step(d1_ - d0_, 6), fs = tick_step(f1_ - f0_, 5);
  for (double d = std::ceil(d0_ / ds) * ds; d <= d1_; d += ds) {
    line(to_x(d), y0_, to_x(d), y1_);
    label(d, to_x(d) - 0.006, y0_ - 0.04, false);
  }
  for (double f = std::ceil(f0_ / fs) * fs; f <= f1_; f += fs) {
    line(x0_, to_y(f), x1_, to_y(f));
    label(f, x0_ - 0.004, to_y(f) - 0.01, true);
  }
  line(x0_, y0_, x1_, y0_);
  line(x0_, y0_, x0_, y1_);
  grid_data_->SetPoints(pts);
  grid_data_->SetLines(lines);
  grid_data_->Modified();
  if (hidden_) hide();
}

void ForceDepthGraph::update(const std::deque<TickSample>& history, double until_s) {
  std::size_t count = 0;
  bool grow = false;
  for (const TickSample& s : history) {
    if (s.time_s > until_s) break;
    ++count;
    const double d = s.depth_m / kMm;
    const double hi = std::max({s.tissue_force_N, s.sent_axial_N, s.lateral_force_N});
    const double lo = std::min(s.tissue_force_N, s.sent_axial_N);
    if (d > d1_) d1_ = 1.25 * d, grow = true;
    if (hi > f1_) f1_ = 1.25 * hi, grow = true;
    if (lo < f0_) f0_ = 1.25 * lo, grow = true;
  }
  if (grow) rebuild_axes();
  auto fill = [&](vtkPolyData* data, double TickSample::*force) {
    vtkPoints* pts = data->GetPoints();
    vtkCellArray* cells = data->GetLines();
    pts->SetNumberOfPoints(static_cast<vtkIdType>(count));
    vtkIdType i = 0;
    for (const TickSample& s : history) {
      if (i == static_cast<vtkIdType>(count)) break;
      pts->SetPoint(i++, to_x(s.depth_m / kMm), to_y(s.*force), 0.0);
    }
    cells->Reset();
    if (count >= 2) {
      cells->InsertNextCell(static_cast<vtkIdType>(count));
      for (vtkIdType k = 0; k < static_cast<vtkIdType>(count); ++k) cells->InsertCellPoint(k);
    }
    pts->Modified();
    cells->Modified();
    data->Modified();
  };
  fill(model_data_, &TickSample::tissue_force_N);
  fill(sent_data_, &TickSample::sent_axial_N);
  fill(lateral_data_, &TickSample::lateral_force_N);
}

void ForceDepthGraph::hide() {
  hidden_ = true;
  background_->VisibilityOff();
  grid_->VisibilityOff();
  model_line_->VisibilityOff();
  sent_line_->VisibilityOff();
  lateral_line_->VisibilityOff();
  for (auto& l : labels_) l->VisibilityOff();
  for (auto& l : titles_) l->VisibilityOff();
}

}  // namespace puncture::realtime
