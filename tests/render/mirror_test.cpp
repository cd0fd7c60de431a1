// The GLFW mirror window, run under Xvfb by ctest: presents frames through a swapchain with no
// validation messages. Without a display it must fail cleanly (the mirror is optional).
#include <gtest/gtest.h>

#include <cstdlib>

#include "render/mirror_window.hpp"
#include "test_scenes.hpp"

namespace drape::render {
namespace {

TEST(MirrorWindow, PresentsFramesOrFailsCleanly) {
  auto exts = MirrorWindow::prepare();
  const char* display = std::getenv("DISPLAY");
  if (!exts) {
    std::printf("no mirror: %s\n", exts.error().c_str());
    EXPECT_TRUE(display == nullptr || *display == 0) << "a display is set but: " << exts.error();
    EXPECT_NE(exts.error().find("mirror"), std::string::npos);
    return;
  }
  RendererOptions opt;
  opt.context.validation = true;
  opt.context.prefer_cpu = true;
  opt.context.instance_extensions = *exts;
  opt.context.swapchain = true;
  auto r = Renderer::create(opt);
  ASSERT_TRUE(r.ok()) << r.error();
  {
    auto win = MirrorWindow::open(**r, 160, 120, "drape mirror test");
    ASSERT_TRUE(win.ok()) << win.error();
    sim::SceneSnapshot s = test::decorated_scene();
    const View v = look_at({0.6f, 1.4f, 1.7f}, {0, 1, 0}, 0.8f, 160.0f / 120.0f);
    for (int i = 0; i < 3; ++i) {
      const Status st = (*win)->show(s, v);
      ASSERT_TRUE(st.ok()) << st.error;
    }
    std::printf("presented %d frames at %dx%d on %s\n", (*win)->frames_presented(), (*win)->width(),
                (*win)->height(), (*r)->device_name().c_str());
    EXPECT_EQ((*win)->frames_presented(), 3);
    EXPECT_EQ((*win)->width(), 160);
  }
  const ValidationCounts vc = (*r)->validation();
  EXPECT_EQ(vc.errors + vc.warnings, 0u);
  for (const auto& m : vc.messages) ADD_FAILURE() << "validation: " << m;
}

}  // namespace
}  // namespace drape::render
