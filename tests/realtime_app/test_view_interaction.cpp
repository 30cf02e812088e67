// The view's mouse and keyboard bindings move the mouse device's needle
// target as documented (events sent to the real VTK interactor of an
// on-screen window under Xvfb), and the view renders a snapshot.
#include <gtest/gtest.h>

#include <vtkCommand.h>
#include <vtkRenderWindowInteractor.h>

#include "puncture/model/realtime_model.hpp"
#include "puncture/scene_io.hpp"
#include "realtime_view.hpp"

namespace puncture::realtime {
namespace {

void key(vtkRenderWindowInteractor* i, const char* sym, bool shift = false) {
  i->SetKeyEventInformation(0, shift ? 1 : 0, sym[1] == '\0' ? sym[0] : 0, 1, sym);
  i->InvokeEvent(vtkCommand::KeyPressEvent, nullptr);
}
void mouse(vtkRenderWindowInteractor* i, unsigned long event, int x, int y, bool shift) {
  i->SetEventInformation(x, y, 0, shift ? 1 : 0);
  i->InvokeEvent(event, nullptr);
}

TEST(ViewInteraction, KeysWheelAndShiftDragMoveTheNeedle) {
  const Scene scene = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json");
  const RealtimeModel model = build_realtime_model(scene);
  PointerDevice pointer(scene, 1e-3);
  ViewOptions options;
  options.width = 400;
  options.height = 300;
  RealtimeView view(scene, model, options, &pointer);
  vtkRenderWindowInteractor* i = view.interactor();
  ASSERT_NE(i, nullptr);
  const Eigen::Vector3d home = pointer.home();
  EXPECT_EQ(pointer.target(), home);

  key(i, "Down");
  EXPECT_NEAR(pointer.target().z(), home.z() - 0.5e-3, 1e-12);
  key(i, "Right");
  EXPECT_NEAR(pointer.target().x(), home.x() + 1e-3, 1e-12);
  key(i, "Prior");
  EXPECT_NEAR(pointer.target().y(), home.y() + 1e-3, 1e-12);
  mouse(i, vtkCommand::MouseWheelBackwardEvent, 200, 150, false);
  EXPECT_NEAR(pointer.target().z(), home.z() - 0.75e-3, 1e-12);
  mouse(i, vtkCommand::MouseWheelForwardEvent, 200, 150, true);  // Shift: fine step
  EXPECT_NEAR(pointer.target().z(), home.z() - 0.70e-3, 1e-12);

  // Shift + drag 40 px down and 20 px right: depth +2 mm, x +1 mm (0.05 mm per pixel).
  const Eigen::Vector3d before = pointer.target();
  mouse(i, vtkCommand::LeftButtonPressEvent, 200, 150, true);
  mouse(i, vtkCommand::MouseMoveEvent, 220, 110, true);
  mouse(i, vtkCommand::LeftButtonReleaseEvent, 220, 110, true);
  EXPECT_NEAR(pointer.target().z(), before.z() - 2e-3, 1e-12);
  EXPECT_NEAR(pointer.target().x(), before.x() + 1e-3, 1e-12);
  // A plain drag turns the camera and leaves the needle alone.
  const Eigen::Vector3d after_drag = pointer.target();
  mouse(i, vtkCommand::LeftButtonPressEvent, 200, 150, false);
  mouse(i, vtkCommand::MouseMoveEvent, 260, 150, false);
  mouse(i, vtkCommand::LeftButtonReleaseEvent, 260, 150, false);
  EXPECT_EQ(pointer.target(), after_drag);

  key(i, "Home");
  EXPECT_EQ(pointer.target(), home);
  // 'n' asks for a fresh tissue; the needle is above the skin, so the device passes it on.
  key(i, "n");
  DeviceInput in;
  pointer.read(0, 0.0, in);
  EXPECT_TRUE(in.fresh_tissue);

  // One frame from a snapshot of the untouched model renders.
  ViewSnapshot snap;
  init_snapshot(snap, *model.simulator);
  view.render(snap, ViewStatus{});
}

}  // namespace
}  // namespace puncture::realtime
