#include "realtime_view.hpp"

#include <vtkActor.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCylinderSource.h>
#include <vtkDiskSource.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPNGWriter.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataNormals.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkWindowToImageFilter.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "puncture/realtime/device.hpp"
#include "puncture/realtime/layer_view_geometry.hpp"
#include "force_depth_graph.hpp"

namespace puncture::realtime {
namespace {

constexpr double kMm = 1e-3;

struct Rgb {
  double r, g, b;
};
/// Layer colours, top to bottom: skin, fat, muscle, then a few more for larger scenes.
const Rgb kLayerColours[] = {{0.93, 0.74, 0.62}, {0.98, 0.86, 0.40}, {0.72, 0.20, 0.22},
                             {0.55, 0.62, 0.80}, {0.60, 0.80, 0.55}, {0.80, 0.60, 0.80}};
Rgb layer_colour(std::size_t k) { return kLayerColours[k % (sizeof kLayerColours / sizeof kLayerColours[0])]; }

vtkSmartPointer<vtkCellArray> triangles_of(const Eigen::MatrixX3i& t) {
  auto cells = vtkSmartPointer<vtkCellArray>::New();
  for (Eigen::Index i = 0; i < t.rows(); ++i) {
    const vtkIdType ids[3] = {t(i, 0), t(i, 1), t(i, 2)};
    cells->InsertNextCell(3, ids);
  }
  return cells;
}

void set_points(vtkPoints* points, const Eigen::MatrixX3d& v) {
  points->SetNumberOfPoints(v.rows());
  for (Eigen::Index i = 0; i < v.rows(); ++i) points->SetPoint(i, v(i, 0), v(i, 1), v(i, 2));
  points->Modified();
}

const char* state_name(LayerState s) {
  switch (s) {
    case LayerState::Untouched: return "untouched";
    case LayerState::Pressed: return "pressed";
    case LayerState::Punctured: return "punctured";
  }
  return "?";
}

}  // namespace

/// Camera and needle control for the mouse device.
class NeedleInteractorStyle : public vtkInteractorStyleTrackballCamera {
 public:
  static NeedleInteractorStyle* New();
  vtkTypeMacro(NeedleInteractorStyle, vtkInteractorStyleTrackballCamera);

  PointerDevice* pointer = nullptr;
  std::function<void()> reset_camera;

  void OnKeyPress() override {
    const std::string key = GetInteractor()->GetKeySym() ? GetInteractor()->GetKeySym() : "";
    if (key == "c") {
      if (reset_camera) reset_camera();
      return;
    }
    if (key == "Escape" || key == "q") {
      GetInteractor()->TerminateApp();
      return;
    }
    if (!pointer) return;
    Eigen::Vector3d t = pointer->target();
    if (key == "Up") t.z() += 0.5 * kMm;
    else if (key == "Down") t.z() -= 0.5 * kMm;
    else if (key == "Left") t.x() -= 1.0 * kMm;
    else if (key == "Right") t.x() += 1.0 * kMm;
    else if (key == "Prior") t.y() += 1.0 * kMm;
    else if (key == "Next") t.y() -= 1.0 * kMm;
    else if (key == "Home") t = pointer->home();
    else if (key == "n") pointer->request_fresh_tissue();
    else return;
    pointer->set_target(t);
  }
  // Swallow VTK's default character bindings (wireframe, stereo, fly-to, ...).
  void OnChar() override {}

  void OnMouseWheelForward() override { move_depth(+1); }
  void OnMouseWheelBackward() override { move_depth(-1); }

  void OnLeftButtonDown() override {
    if (pointer && GetInteractor()->GetShiftKey()) {
      dragging_ = true;
      GetInteractor()->GetEventPosition(last_);
      return;
    }
    vtkInteractorStyleTrackballCamera::OnLeftButtonDown();
  }
  void OnLeftButtonUp() override {
    if (dragging_) {
      dragging_ = false;
      return;
    }
    vtkInteractorStyleTrackballCamera::OnLeftButtonUp();
  }
  void OnMouseMove() override {
    if (!dragging_) {
      vtkInteractorStyleTrackballCamera::OnMouseMove();
      return;
    }
    int now[2];
    GetInteractor()->GetEventPosition(now);
    Eigen::Vector3d t = pointer->target();
    t.x() += 0.05 * kMm * (now[0] - last_[0]);
    t.z() += 0.05 * kMm * (now[1] - last_[1]);
    pointer->set_target(t);
    last_[0] = now[0];
    last_[1] = now[1];
  }

 private:
  void move_depth(int direction) {
    if (!pointer) return;
    Eigen::Vector3d t = pointer->target();
    t.z() += direction * (GetInteractor()->GetShiftKey() ? 0.05 : 0.25) * kMm;
    pointer->set_target(t);
  }
  bool dragging_ = false;
  int last_[2] = {0, 0};
};
vtkStandardNewMacro(NeedleInteractorStyle);

struct RealtimeView::Impl {
  struct LayerActors {
    LayerViewMesh mesh;
    std::unique_ptr<LayerDeformer> deformer;
    Eigen::MatrixX3d vertices;
    vtkSmartPointer<vtkPoints> points;
    vtkSmartPointer<vtkPolyData> shell, cap;
    vtkSmartPointer<vtkActor> shell_actor, cap_actor, hole_actor, nodes_actor;
    vtkSmartPointer<vtkPoints> node_points;
    vtkSmartPointer<vtkPolyData> nodes;
    bool drawn = false, drawn_valid = false;  ///< what the drawn surface was deformed from
    Eigen::Matrix3Xd drawn_current, drawn_rest;
  };

  Scene scene;
  ViewOptions options;
  PointerDevice* pointer = nullptr;
  vtkSmartPointer<vtkRenderWindow> window;
  vtkSmartPointer<vtkRenderer> renderer;
  vtkSmartPointer<vtkRenderWindowInteractor> interactor;
  std::vector<LayerActors> layers;
  vtkSmartPointer<vtkActor> needle_actor;
  double needle_length_m = 0.06;
  vtkSmartPointer<vtkTextActor> text, help;
  ForceDepthGraph graph;
  std::deque<TickSample> history;
  std::uint64_t history_generation = 0;
  std::int64_t sample_counter = 0;
  std::int64_t frame_count = 0;

  void reset_camera() {
    vtkCamera* c = renderer->GetActiveCamera();
    const double R = 0.5 * scene.sample.diameter_m;
    c->SetFocalPoint(0.05 * R, 0.2 * R, -0.25 * R);
    c->SetPosition(0.6 * R, -1.5 * R, 0.7 * R);
    c->SetViewUp(0.0, 0.0, 1.0);
    c->SetViewAngle(30.0);
    renderer->ResetCameraClippingRange();
  }

  // Building the scene graph (the constructor), in drawing order.
  void create_window();
  void add_layer(std::size_t k, const RealtimeModel& model);
  void add_top_face(LayerActors& a, const Rgb& c);
  void add_side_wall(const LayerActors& a);
  void add_cap(LayerActors& a, const Rgb& c);
  void add_hole(LayerActors& a);
  void add_nodes(LayerActors& a);
  void add_needle();
  void add_overlay();
  void create_interactor();

  void update_text(const ViewSnapshot& snap, const ViewStatus& status);
};

void RealtimeView::Impl::create_window() {
  window = vtkSmartPointer<vtkRenderWindow>::New();
  window->SetSize(options.width, options.height);
  window->SetWindowName(options.title.c_str());
  window->SetMultiSamples(0);  // multisampling costs 4x in software rendering (llvmpipe)
  if (options.offscreen) window->SetOffScreenRendering(1);

  renderer = vtkSmartPointer<vtkRenderer>::New();
  renderer->SetBackground(0.20, 0.23, 0.29);  // solid: a gradient costs a full-screen pass in software rendering
  window->AddRenderer(renderer);
}

// Layers: back half of the top face and side wall, and the cut face at y = 0.
void RealtimeView::Impl::add_layer(std::size_t k, const RealtimeModel& model) {
  LayerActors a;
  a.mesh = build_layer_view_mesh(*model.surfaces[k], layer_disc(scene, k).bottom_z_m);
  const PunctureSimulator& sim = *model.simulator;
  if (const ForceMesh* fm = sim.force_mesh(k))
    a.deformer = std::make_unique<LayerDeformer>(fm->lattice(), scene.layers[k].force_mesh.spacing_L_m);
  a.vertices = a.mesh.rest_vertices;
  a.points = vtkSmartPointer<vtkPoints>::New();
  a.points->SetDataTypeToDouble();
  set_points(a.points, a.vertices);
  const Rgb c = layer_colour(k);
  add_top_face(a, c);
  add_side_wall(a);
  add_cap(a, c);
  add_hole(a);
  add_nodes(a);
  layers.push_back(std::move(a));
}

// Top face: points shared with the cap, updated when the force mesh moves;
// its normals are recomputed then.
void RealtimeView::Impl::add_top_face(LayerActors& a, const Rgb& c) {
  a.shell = vtkSmartPointer<vtkPolyData>::New();
  a.shell->SetPoints(a.points);
  a.shell->SetPolys(triangles_of(a.mesh.top_triangles));
  vtkNew<vtkPolyDataNormals> normals;
  normals->SetInputData(a.shell);
  normals->SplittingOff();  // a smooth surface: no feature edges to split
  normals->ConsistencyOff();
  normals->AutoOrientNormalsOff();
  vtkNew<vtkPolyDataMapper> shell_mapper;
  shell_mapper->SetInputConnection(normals->GetOutputPort());
  a.shell_actor = vtkSmartPointer<vtkActor>::New();
  a.shell_actor->SetMapper(shell_mapper);
  a.shell_actor->GetProperty()->SetColor(c.r, c.g, c.b);
  a.shell_actor->GetProperty()->SetAmbient(0.30);
  a.shell_actor->GetProperty()->SetDiffuse(0.75);
  a.shell_actor->GetProperty()->SetSpecular(0.15);
  a.shell_actor->GetProperty()->SetSpecularPower(20.0);
  a.shell_actor->GetProperty()->BackfaceCullingOn();
  renderer->AddActor(a.shell_actor);
}

// Side wall: its own points, never deformed; the top face's material.
void RealtimeView::Impl::add_side_wall(const LayerActors& a) {
  vtkNew<vtkPoints> side_points;
  side_points->SetDataTypeToDouble();
  set_points(side_points, a.mesh.rest_vertices);
  vtkNew<vtkPolyData> side;
  side->SetPoints(side_points);
  side->SetPolys(triangles_of(a.mesh.side_triangles));
  vtkNew<vtkPolyDataNormals> side_normals;
  side_normals->SetInputData(side);
  side_normals->SplittingOff();
  side_normals->ConsistencyOff();
  side_normals->AutoOrientNormalsOff();
  vtkNew<vtkPolyDataMapper> side_mapper;
  side_mapper->SetInputConnection(side_normals->GetOutputPort());
  vtkNew<vtkActor> side_actor;
  side_actor->SetMapper(side_mapper);
  side_actor->SetProperty(a.shell_actor->GetProperty());
  renderer->AddActor(side_actor);
}

// The cut face at y = 0, a shade darker than the top face.
void RealtimeView::Impl::add_cap(LayerActors& a, const Rgb& c) {
  a.cap = vtkSmartPointer<vtkPolyData>::New();
  a.cap->SetPoints(a.points);
  a.cap->SetPolys(triangles_of(a.mesh.cap_triangles));
  vtkNew<vtkPolyDataMapper> cap_mapper;
  cap_mapper->SetInputData(a.cap);
  a.cap_actor = vtkSmartPointer<vtkActor>::New();
  a.cap_actor->SetMapper(cap_mapper);
  a.cap_actor->GetProperty()->SetColor(0.85 * c.r, 0.85 * c.g, 0.85 * c.b);
  a.cap_actor->GetProperty()->SetAmbient(0.35);
  a.cap_actor->GetProperty()->SetDiffuse(0.70);
  a.cap_actor->GetProperty()->BackfaceCullingOn();
  renderer->AddActor(a.cap_actor);
}

// Puncture hole: a dark ring around the needle at the entry point.
void RealtimeView::Impl::add_hole(LayerActors& a) {
  vtkNew<vtkDiskSource> disk;
  disk->SetInnerRadius(scene.needle.radius_m);
  disk->SetOuterRadius(3.0 * scene.needle.radius_m);
  disk->SetCircumferentialResolution(48);
  vtkNew<vtkPolyDataMapper> disk_mapper;
  disk_mapper->SetInputConnection(disk->GetOutputPort());
  a.hole_actor = vtkSmartPointer<vtkActor>::New();
  a.hole_actor->SetMapper(disk_mapper);
  a.hole_actor->GetProperty()->SetColor(0.30, 0.05, 0.05);
  a.hole_actor->GetProperty()->LightingOff();
  a.hole_actor->VisibilityOff();
  renderer->AddActor(a.hole_actor);
}

// Force-mesh nodes (back half), shown while the layer is pressed or resuming.
void RealtimeView::Impl::add_nodes(LayerActors& a) {
  a.node_points = vtkSmartPointer<vtkPoints>::New();
  a.nodes = vtkSmartPointer<vtkPolyData>::New();
  a.nodes->SetPoints(a.node_points);
  a.nodes->SetVerts(vtkSmartPointer<vtkCellArray>::New());
  vtkNew<vtkPolyDataMapper> node_mapper;
  node_mapper->SetInputData(a.nodes);
  a.nodes_actor = vtkSmartPointer<vtkActor>::New();
  a.nodes_actor->SetMapper(node_mapper);
  a.nodes_actor->GetProperty()->SetColor(0.12, 0.16, 0.45);
  a.nodes_actor->GetProperty()->SetPointSize(4.0);
  renderer->AddActor(a.nodes_actor);
}

// Needle: a cylinder along its axis, ending at the tip.
void RealtimeView::Impl::add_needle() {
  vtkNew<vtkCylinderSource> cylinder;
  cylinder->SetRadius(scene.needle.radius_m);
  needle_length_m = 0.5 * scene.sample.diameter_m + scene.insertion.start_height_m;
  cylinder->SetHeight(needle_length_m);
  cylinder->SetResolution(24);
  vtkNew<vtkPolyDataMapper> needle_mapper;
  needle_mapper->SetInputConnection(cylinder->GetOutputPort());
  needle_actor = vtkSmartPointer<vtkActor>::New();
  needle_actor->SetMapper(needle_mapper);
  needle_actor->GetProperty()->SetColor(0.80, 0.82, 0.86);
  needle_actor->GetProperty()->SetSpecular(0.8);
  needle_actor->GetProperty()->SetSpecularPower(60.0);
  renderer->AddActor(needle_actor);
}

// Overlay text, and the key bindings at the bottom of an interactive window with the mouse device.
void RealtimeView::Impl::add_overlay() {
  text = vtkSmartPointer<vtkTextActor>::New();
  text->GetTextProperty()->SetFontFamilyToCourier();
  text->GetTextProperty()->SetFontSize(16);
  text->GetTextProperty()->SetColor(0.95, 0.95, 0.95);
  text->GetTextProperty()->SetVerticalJustificationToTop();
  text->GetPositionCoordinate()->SetCoordinateSystemToNormalizedDisplay();
  text->GetPositionCoordinate()->SetValue(0.01, 0.985);
  renderer->AddViewProp(text);
  if (pointer && !options.offscreen) {
    help = vtkSmartPointer<vtkTextActor>::New();
    help->SetInput(
        "wheel, Up/Down: depth   Shift+drag: depth and x   Left/Right, PgUp/PgDn: x, y   Home: start   "
        "n: fresh tissue   c: camera   q: quit");
    help->GetTextProperty()->SetFontSize(13);
    help->GetTextProperty()->SetColor(0.8, 0.85, 0.9);
    help->GetPositionCoordinate()->SetCoordinateSystemToNormalizedDisplay();
    help->GetPositionCoordinate()->SetValue(0.01, 0.01);
    renderer->AddViewProp(help);
  }
}

void RealtimeView::Impl::create_interactor() {
  interactor = vtkSmartPointer<vtkRenderWindowInteractor>::New();
  interactor->SetRenderWindow(window);
  vtkNew<NeedleInteractorStyle> style;
  style->pointer = pointer;
  Impl* impl = this;
  style->reset_camera = [impl] { impl->reset_camera(); };
  interactor->SetInteractorStyle(style);
  interactor->Initialize();
}

RealtimeView::RealtimeView(const Scene& scene, const RealtimeModel& model, ViewOptions options, PointerDevice* pointer)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.scene = scene;
  m.options = options;
  m.pointer = pointer;
  m.create_window();
  for (std::size_t k = 0; k < scene.layers.size(); ++k) m.add_layer(k, model);
  m.add_needle();
  m.add_overlay();
  // Live force-depth graph in the lower right corner.
  m.graph.build(m.renderer, 0.60, 0.06, 0.985, 0.46, std::max(scene.insertion.target_depth_m, 5e-3) / kMm,
                std::max(0.5, options.graph_max_force_N));
  m.reset_camera();
  if (!options.offscreen) m.create_interactor();
}

RealtimeView::~RealtimeView() = default;

void RealtimeView::add_sample(const TickSample& s) {
  Impl& m = *impl_;
  if (s.model_generation != m.history_generation) {
    m.history.clear();  // a fresh tissue: a new force-depth curve
    m.history_generation = s.model_generation;
  }
  // Keep every fourth tick (250 Hz at 1 kHz) of the last 16 s.
  if ((m.sample_counter++ & 3) == 0) m.history.push_back(s);
  while (m.history.size() > 4000) m.history.pop_front();
}

void RealtimeView::render(const ViewSnapshot& snap, const ViewStatus& status, bool force_text, double graph_until_s) {
  Impl& m = *impl_;
  for (std::size_t k = 0; k < m.layers.size(); ++k) {
    Impl::LayerActors& a = m.layers[k];
    const bool have = k < snap.layers.size();
    if (!have) continue;
    // Deform (and upload, and recompute normals) only when the force mesh moved.
    const LayerSnapshot& now = snap.layers[k];
    const bool moved = !a.drawn || now.nodes_valid != a.drawn_valid ||
                       (now.nodes_valid && (now.current_m != a.drawn_current || now.rest_m != a.drawn_rest));
    if (moved && a.deformer) {
      a.deformer->apply(now, a.mesh, a.vertices);
      set_points(a.points, a.vertices);
      a.shell->Modified();
      a.cap->Modified();
    }
    a.drawn = true;
    a.drawn_valid = now.nodes_valid;
    if (now.nodes_valid) a.drawn_current = now.current_m, a.drawn_rest = now.rest_m;
    const LayerSnapshot& l = snap.layers[k];
    const bool punctured = l.state == LayerState::Punctured && l.has_contact;
    a.hole_actor->SetVisibility(punctured);
    if (punctured) a.hole_actor->SetPosition(l.contact_m.x(), l.contact_m.y(), l.contact_m.z() + 0.05 * kMm);
    a.node_points->Reset();
    vtkCellArray* verts = a.nodes->GetVerts();
    verts->Reset();
    if (l.nodes_valid && l.state != LayerState::Untouched) {
      for (Eigen::Index i = 0; i < l.current_m.cols(); ++i) {
        const Eigen::Vector3d p = l.current_m.col(i);
        if (p.y() < -1e-9) continue;
        const vtkIdType id = a.node_points->InsertNextPoint(p.x(), p.y(), p.z() + 0.03 * kMm);
        verts->InsertNextCell(1, &id);
      }
    }
    a.node_points->Modified();
    verts->Modified();
    a.nodes->Modified();
  }

  // Needle.
  const Eigen::Vector3d dir = snap.needle.direction.normalized();
  const Eigen::Vector3d centre = snap.needle.tip_position_m - 0.5 * m.needle_length_m * dir;
  const Eigen::Matrix3d rot = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitY(), dir).toRotationMatrix();
  vtkNew<vtkMatrix4x4> pose;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) pose->SetElement(r, c, rot(r, c));
    pose->SetElement(r, 3, centre[r]);
  }
  m.needle_actor->SetUserMatrix(pose);

  // The overlay's text is rasterised again whenever it changes: 15 times a second is enough.
  if (force_text || m.frame_count++ % 4 == 0) m.update_text(snap, status);
  m.graph.update(m.history, graph_until_s);
  m.renderer->ResetCameraClippingRange();
  m.window->Render();
}

void RealtimeView::Impl::update_text(const ViewSnapshot& snap, const ViewStatus& status) {
  std::ostringstream t;
  t << std::fixed;
  t << "puncture-app   scene " << status.scene_name << "   device " << status.device_name << "\n";
  t << std::setprecision(3) << "t " << snap.needle.time_s << " s   depth " << std::setprecision(2)
    << snap.needle.depth_m() / kMm << " mm   v " << snap.needle.axial_velocity_m_per_s / kMm << " mm/s\n";
  t << std::setprecision(3) << "force " << snap.tissue_force_N << " N (tip " << snap.tip_force_N << ", cutting "
    << snap.cutting_force_N << ", friction " << snap.friction_force_N << ")   across " << snap.lateral_force_N
    << " N   to device " << snap.force_sent_N.norm()
    << " N" << ((snap.flags & kOutMagnitudeClamped) ? "  [magnitude limit]" : "")
    << ((snap.flags & kOutRateClamped) ? "  [rate limit]" : "") << ((snap.flags & kOutNoPose) ? "  [no pose]" : "")
    << "\n";
  for (std::size_t k = 0; k < snap.layers.size() && k < scene.layers.size(); ++k) {
    const LayerSnapshot& l = snap.layers[k];
    t << "  " << std::left << std::setw(8) << scene.layers[k].name << std::setw(10) << state_name(l.state)
      << std::right << std::setprecision(3);
    if (l.state == LayerState::Pressed) {
      if (l.support_force_N != 0.0 && l.surface_force_N == 0.0)
        t << "  support " << l.support_force_N << " N";
      else
        t << "  surface " << l.surface_force_N << " N  rings " << l.deformed_rings;
    }
    if (l.state == LayerState::Punctured) {
      if (l.cutting_force_N != 0.0) t << "  cutting " << l.cutting_force_N << " N";
      t << "  friction " << l.friction_force_N << " N  damping " << l.damping_force_N << " N";
    }
    t << "\n";
  }
  t << std::setprecision(1) << "haptic " << status.haptic_rate_Hz << " Hz   missed " << status.missed_deadlines
    << "   view " << status.view_fps << " fps (last second)";
  if (!status.note.empty()) t << "\n" << status.note;
  for (const std::string& w : status.warnings) t << "\nwarning: " << (w.size() > 90 ? w.substr(0, 87) + "..." : w);
  text->SetInput(t.str().c_str());
}

void RealtimeView::screenshot(const std::string& png_path) {
  Impl& m = *impl_;
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(m.window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->ShouldRerenderOff();
  grab->Update();
  const std::string partial = png_path + ".partial.png";
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(partial.c_str());
  writer->SetInputConnection(grab->GetOutputPort());
  writer->Write();
  std::error_code ec;
  if (!std::filesystem::exists(partial) || std::filesystem::file_size(partial, ec) == 0) {
    std::filesystem::remove(partial, ec);
    throw std::runtime_error(png_path + ": cannot write the screenshot");
  }
  std::filesystem::rename(partial, png_path, ec);
  if (ec) throw std::runtime_error(png_path + ": cannot rename the screenshot: " + ec.message());
}

vtkRenderWindowInteractor* RealtimeView::interactor() { return impl_->interactor; }

void RealtimeView::run_interactive(int period_ms, const std::function<bool()>& on_frame) {
  Impl& m = *impl_;
  if (!m.interactor) throw std::logic_error("run_interactive: the view is offscreen");
  struct Context {
    std::function<bool()> on_frame;
    vtkRenderWindowInteractor* interactor;
  } context{on_frame, m.interactor};
  vtkNew<vtkCallbackCommand> timer;
  timer->SetClientData(&context);
  timer->SetCallback([](vtkObject*, unsigned long, void* data, void*) {
    auto* c = static_cast<Context*>(data);
    if (!c->on_frame()) c->interactor->TerminateApp();
  });
  m.interactor->AddObserver(vtkCommand::TimerEvent, timer);
  m.interactor->CreateRepeatingTimer(static_cast<unsigned long>(std::max(1, period_ms)));
  m.window->Render();
  m.interactor->Start();
}

}  // namespace puncture::realtime
