// The feedback panel's text: the glyph atlas from the Debian font, the panel's layout, and the
// panel drawn by the renderer on lavapipe (glyph pixels inside the panel's rectangle, different
// strings giving different images, nothing outside the panel changed, the caller's depth image
// untouched) and the clear error of a missing font. Every GPU test ends with zero validation
// messages.
#include "render/text.hpp"

#include <gtest/gtest.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>

#include "render/image_io.hpp"
#include "render/renderer.hpp"
#include "test_scenes.hpp"

namespace drape::render {
namespace {

void expect_no_validation_messages(const Renderer& r) {
  const ValidationCounts v = r.validation();
  EXPECT_EQ(v.errors + v.warnings, 0u);
  for (const auto& m : v.messages) ADD_FAILURE() << "validation: " << m;
}

TEST(Text, AtlasFromTheDebianFont) {
  auto font = load_font_atlas(default_font_path(), 32);
  ASSERT_TRUE(font.ok()) << font.error();
  EXPECT_EQ(font->pixel_size, 32);
  EXPECT_GT(font->line_height, 32.0f);
  // Printable ASCII and the arrow of the sim's messages.
  for (uint32_t c = 33; c < 127; ++c) ASSERT_TRUE(font->glyphs.count(c)) << c;
  EXPECT_TRUE(font->glyphs.count(0x2192));
  const Glyph& m = font->glyphs.at('M');
  EXPECT_GT(m.w, 10);
  EXPECT_GT(m.h, 15);
  // The 'M' is drawn: its rectangle holds fully covered pixels.
  int covered = 0;
  for (int y = m.y; y < m.y + m.h; ++y)
    for (int x = m.x; x < m.x + m.w; ++x) covered += font->alpha[y * font->width + x] > 200;
  EXPECT_GT(covered, m.w * m.h / 5);
}

TEST(Text, MissingFontIsAnErrorNamingTheFile) {
  const std::string path = "/nonexistent/fonts/NoSuchFont.ttf";
  auto font = load_font_atlas(path);
  ASSERT_FALSE(font.ok());
  EXPECT_NE(font.error().find(path), std::string::npos) << font.error();
  EXPECT_NE(font.error().find("fonts-dejavu-core"), std::string::npos) << font.error();
  // A file that is not a font.
  const std::string bad = std::string(DRAPE_BINARY_DIR) + "/not_a_font.ttf";
  {
    std::FILE* f = std::fopen(bad.c_str(), "w");
    ASSERT_TRUE(f);
    std::fputs("hello", f);
    std::fclose(f);
  }
  auto bad_font = load_font_atlas(bad);
  ASSERT_FALSE(bad_font.ok());
  EXPECT_NE(bad_font.error().find(bad), std::string::npos) << bad_font.error();
}

TEST(Text, WrapsLongLinesAtSpaces) {
  const auto w = wrap_lines({"pinch: nothing within 3 cm of the right hand to pinch", "ok"}, 20);
  ASSERT_GE(w.size(), 4u);
  for (const auto& l : w) EXPECT_LE(l.size(), 20u) << l;
  EXPECT_EQ(w[0], "pinch: nothing");
  EXPECT_EQ(w[1].substr(0, 2), "  ");  // continuation indented
  EXPECT_EQ(w.back(), "ok");
  // A word longer than a line is cut.
  const auto c = wrap_lines({std::string(30, 'x')}, 10);
  ASSERT_EQ(c.size(), 4u);
  EXPECT_EQ(c[0], std::string(10, 'x'));
}

TEST(Text, PanelHasARectangleAndAQuadPerVisibleGlyph) {
  auto font = load_font_atlas(default_font_path(), 32);
  ASSERT_TRUE(font.ok()) << font.error();
  const TextMesh m = build_text_panel(*font, {"left hand: -", "AB C"});
  // Background + 10 + 3 glyphs (spaces draw nothing).
  EXPECT_EQ(m.vertices.size(), 4u * (1 + 10 + 3));
  EXPECT_EQ(m.indices.size(), 6u * (1 + 10 + 3));
  EXPECT_FLOAT_EQ(m.width, 0.30f);
  EXPECT_GT(m.height, 2 * 0.014f);
  // Every glyph inside the rectangle.
  for (const auto& v : m.vertices) {
    EXPECT_GE(v.pos[0], -0.5f * m.width - 1e-6f);
    EXPECT_LE(v.pos[0], 0.5f * m.width + 1e-6f);
    EXPECT_LE(v.pos[1], 1e-6f);
    EXPECT_GE(v.pos[1], -m.height - 1e-6f);
  }
  // Many lines shrink to the maximum height.
  const TextMesh tall = build_text_panel(*font, std::vector<std::string>(60, "line"));
  EXPECT_LE(tall.height, 0.30f + 1e-5f);
  EXPECT_TRUE(build_text_panel(*font, {}).vertices.empty());
}

// The panel's rectangle in the image (pixels), from its corners.
struct Rect {
  int x0, y0, x1, y1;
};
Rect panel_rect(const View& v, const TextPanel& p, float height, int w, int h) {
  const Mat4f m = head_locked_panel(p.head, height);
  Rect r{w, h, 0, 0};
  for (float x : {-0.5f * p.style.width, 0.5f * p.style.width})
    for (float y : {0.0f, -height}) {
      const Eigen::Vector4f q = m * Eigen::Vector4f(x, y, 0, 1);
      auto px = project_to_pixel(v, q.head<3>(), w, h);
      EXPECT_TRUE(px.has_value());
      if (!px) continue;
      r.x0 = std::min(r.x0, static_cast<int>(px->x()));
      r.y0 = std::min(r.y0, static_cast<int>(px->y()));
      r.x1 = std::max(r.x1, static_cast<int>(px->x()) + 1);
      r.y1 = std::max(r.y1, static_cast<int>(px->y()) + 1);
    }
  return r;
}

double process_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

int luma(const uint8_t* p) {
  return (p[0] * 3 + p[1] * 6 + p[2]) / 10;
}

TEST(TextPanel, DrawnOverTheSceneWithGlyphsInsideItsRectangle) {
  auto r = test::make_test_renderer();
  ASSERT_TRUE(r);
  sim::SceneSnapshot s = test::decorated_scene();
  const int W = 960, H = 720;
  const View v = look_at({0.0f, 1.45f, 1.2f}, {0.0f, 1.1f, 0.0f}, 1.2f, float(W) / H);
  auto plain = r->render_offscreen(s, v, W, H);
  ASSERT_TRUE(plain.ok()) << plain.error();
  TextPanel p;
  p.lines = {"voice: listening (say \"show help\")", "left hand: -",
             "right hand: pinching particle 12", "voice: heard \"pin here\" -> pin",
             "pinch: nothing within 3 cm of the left hand to pinch"};
  p.version = 1;
  p.head = pose_of(v);
  r->set_text_panel(p);
  auto a = r->render_offscreen(s, v, W, H);
  ASSERT_TRUE(a.ok()) << a.error();
  EXPECT_EQ(r->text_error(), "");
  p.lines[4] = "cut: ignored: stroke has fewer than 2 samples";
  p.version = 2;
  r->set_text_panel(p);
  auto b = r->render_offscreen(s, v, W, H);
  ASSERT_TRUE(b.ok()) << b.error();
  auto font = load_font_atlas(default_font_path());
  ASSERT_TRUE(font.ok());
  const float height = build_text_panel(*font, p.lines).height;
  const Rect rc = panel_rect(v, p, height, W, H);
  std::printf("panel rectangle: x %d..%d, y %d..%d\n", rc.x0, rc.x1, rc.y0, rc.y1);
  ASSERT_GT(rc.x1 - rc.x0, W / 4);  // 0.3 m at 0.55 m: about a third of a 1.2 rad view
  ASSERT_GT(rc.y1 - rc.y0, 10);
  int bright = 0, dark = 0, ab_differ = 0, outside_changed = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const bool inside = x >= rc.x0 && x < rc.x1 && y >= rc.y0 && y < rc.y1;
      const bool near = x >= rc.x0 - 2 && x < rc.x1 + 2 && y >= rc.y0 - 2 && y < rc.y1 + 2;
      const uint8_t *pa = a->px(x, y), *pb = b->px(x, y), *p0 = plain->px(x, y);
      if (inside) {
        bright += luma(pa) > 200;
        dark += luma(pa) < luma(p0) - 40;  // darkened by the panel
        ab_differ += std::abs(luma(pa) - luma(pb)) > 60;
      } else if (!near) {
        outside_changed += std::memcmp(pa, p0, 4) != 0;
      }
    }
  std::printf(
      "inside: %d glyph pixels, %d dark pixels, %d differ between strings; outside "
      "changed: %d\n",
      bright, dark, ab_differ, outside_changed);
  const int area = (rc.x1 - rc.x0) * (rc.y1 - rc.y0);
  EXPECT_GT(bright, 150);         // the letters
  EXPECT_GT(dark, area / 2);      // the dark rectangle behind them
  EXPECT_GT(ab_differ, 50);       // a different last line
  EXPECT_EQ(outside_changed, 0);  // nothing else drawn
  // No lines: the scene alone again, byte for byte.
  r->set_text_panel(TextPanel{});
  auto none = r->render_offscreen(s, v, W, H);
  ASSERT_TRUE(none.ok());
  EXPECT_EQ(none->rgba, plain->rgba);
  const std::string out = std::string(DRAPE_BINARY_DIR) + "/render_text";
  std::filesystem::create_directories(out);
  EXPECT_EQ(write_png(out + "/panel.png", *a), "");
  expect_no_validation_messages(*r);
}

TEST(TextPanel, MissingFontLeavesThePanelOutWithAClearError) {
  RendererOptions opt;
  opt.context.validation = true;
  opt.context.prefer_cpu = true;
  opt.font_path = "/nonexistent/fonts/NoSuchFont.ttf";
  auto r = Renderer::create(opt);
  ASSERT_TRUE(r.ok()) << r.error();
  sim::SceneSnapshot s = test::decorated_scene();
  const View v = look_at({0.0f, 1.45f, 1.2f}, {0.0f, 1.1f, 0.0f}, 1.2f, 1.0f);
  auto plain = (*r)->render_offscreen(s, v, 128, 128);
  ASSERT_TRUE(plain.ok());
  TextPanel p;
  p.lines = {"left hand: -"};
  p.version = 1;
  p.head = pose_of(v);
  (*r)->set_text_panel(p);
  auto img = (*r)->render_offscreen(s, v, 128, 128);
  ASSERT_TRUE(img.ok()) << img.error();  // the frame is drawn ...
  EXPECT_EQ(img->rgba, plain->rgba);     // ... without the panel
  EXPECT_NE((*r)->text_error().find(opt.font_path), std::string::npos) << (*r)->text_error();
  expect_no_validation_messages(**r);
}

// A colour and a D32 depth image of the renderer's device, as an XR runtime hands them over.
struct Images {
  VkDevice dev = VK_NULL_HANDLE;
  VkImage color = VK_NULL_HANDLE, depth = VK_NULL_HANDLE;
  VkDeviceMemory mem[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
  ~Images() {
    for (VkImage i : {color, depth})
      if (i) vkDestroyImage(dev, i, nullptr);
    for (VkDeviceMemory m : mem)
      if (m) vkFreeMemory(dev, m, nullptr);
  }
};

uint32_t memory_type(const VulkanContext& c, uint32_t bits, VkMemoryPropertyFlags want) {
  for (uint32_t i = 0; i < c.memory.memoryTypeCount; ++i)
    if ((bits & (1u << i)) && (c.memory.memoryTypes[i].propertyFlags & want) == want) return i;
  return 0;
}

void make_images(VulkanContext& c, uint32_t w, uint32_t h, Images& im) {
  im.dev = c.device;
  VkImageCreateInfo ii{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ii.imageType = VK_IMAGE_TYPE_2D;
  ii.extent = {w, h, 1};
  ii.mipLevels = 1;
  ii.arrayLayers = 1;
  ii.samples = VK_SAMPLE_COUNT_1_BIT;
  ii.tiling = VK_IMAGE_TILING_OPTIMAL;
  for (int k = 0; k < 2; ++k) {
    ii.format = k == 0 ? VK_FORMAT_R8G8B8A8_SRGB : VK_FORMAT_D32_SFLOAT;
    ii.usage = (k == 0 ? VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT
                       : VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT) |
               VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    VkImage& img = k == 0 ? im.color : im.depth;
    ASSERT_EQ(vkCreateImage(c.device, &ii, nullptr, &img), VK_SUCCESS);
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(c.device, img, &req);
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = memory_type(c, req.memoryTypeBits, 0);
    ASSERT_EQ(vkAllocateMemory(c.device, &ai, nullptr, &im.mem[k]), VK_SUCCESS);
    vkBindImageMemory(c.device, img, im.mem[k], 0);
  }
}

// The depth image's floats (it is left in DEPTH_STENCIL_ATTACHMENT_OPTIMAL by the renderer).
std::vector<float> read_depth(VulkanContext& c, VkImage depth, uint32_t w, uint32_t h) {
  std::vector<float> out(size_t(w) * h, -1.0f);
  VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bi.size = out.size() * sizeof(float);
  bi.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  VkBuffer buf = VK_NULL_HANDLE;
  vkCreateBuffer(c.device, &bi, nullptr, &buf);
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(c.device, buf, &req);
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  ai.allocationSize = req.size;
  ai.memoryTypeIndex =
      memory_type(c, req.memoryTypeBits,
                  VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  VkDeviceMemory mem = VK_NULL_HANDLE;
  vkAllocateMemory(c.device, &ai, nullptr, &mem);
  vkBindBufferMemory(c.device, buf, mem, 0);
  VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pi.queueFamilyIndex = c.queue_family;
  VkCommandPool pool = VK_NULL_HANDLE;
  vkCreateCommandPool(c.device, &pi, nullptr, &pool);
  VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cai.commandPool = pool;
  cai.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  vkAllocateCommandBuffers(c.device, &cai, &cmd);
  VkCommandBufferBeginInfo cbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  vkBeginCommandBuffer(cmd, &cbi);
  VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  b.oldLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
  b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  b.srcAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = depth;
  b.subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
                       VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr, 1, &b);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
  region.imageExtent = {w, h, 1};
  vkCmdCopyImageToBuffer(cmd, depth, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buf, 1, &region);
  vkEndCommandBuffer(cmd);
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  vkQueueSubmit(c.queue, 1, &si, VK_NULL_HANDLE);
  vkQueueWaitIdle(c.queue);
  void* mapped = nullptr;
  vkMapMemory(c.device, mem, 0, VK_WHOLE_SIZE, 0, &mapped);
  std::memcpy(out.data(), mapped, out.size() * sizeof(float));
  vkUnmapMemory(c.device, mem);
  vkDestroyCommandPool(c.device, pool, nullptr);
  vkDestroyBuffer(c.device, buf, nullptr);
  vkFreeMemory(c.device, mem, nullptr);
  return out;
}

// With a caller's depth image (the depth an XR runtime reads to place the hand on the cloth),
// the panel changes nothing of it.
TEST(TextPanel, LeavesTheCallersDepthUntouched) {
  auto r = test::make_test_renderer();
  ASSERT_TRUE(r);
  const uint32_t W = 160, H = 120;
  Images im;
  make_images(r->context(), W, H, im);
  ASSERT_TRUE(im.color && im.depth);
  sim::SceneSnapshot s = test::decorated_scene();
  const View v = look_at({0.0f, 1.45f, 1.2f}, {0.0f, 1.1f, 0.0f}, 1.2f, float(W) / H);
  ColorTarget t{im.color, VK_FORMAT_R8G8B8A8_SRGB, W, H, 0, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                im.depth, VK_FORMAT_D32_SFLOAT};
  ASSERT_TRUE(r->render(s, v, t).ok());
  const std::vector<float> plain = read_depth(r->context(), im.depth, W, H);
  TextPanel p;
  p.lines = {"left hand: -", "right hand: cutting", "pinch: nothing within 3 cm to pinch"};
  p.version = 1;
  p.head = pose_of(v);
  r->set_text_panel(p);
  const Status st = r->render(s, v, t);
  ASSERT_TRUE(st.ok()) << st.error;
  ASSERT_EQ(r->text_error(), "");
  const std::vector<float> with_panel = read_depth(r->context(), im.depth, W, H);
  int scene_px = 0;
  for (float d : plain) scene_px += d < 1.0f;
  EXPECT_GT(scene_px, int(W * H) / 4);  // the depth holds the scene
  EXPECT_EQ(with_panel, plain);
  r->forget_targets();
  expect_no_validation_messages(*r);
}

// Two 512² eyes with one submission, as the XR app draws them: the panel's quads are built once
// per version, and what the panel costs is printed (the median of 15 frames each way).
TEST(TextPanel, QuadsRebuiltOnlyWhenTheVersionChanges) {
  auto r = test::make_test_renderer();
  ASSERT_TRUE(r);
  sim::SceneSnapshot s = test::decorated_scene();
  const uint32_t W = 512;
  Images im[2];
  ViewTarget vt[2];
  for (int e = 0; e < 2; ++e) {
    make_images(r->context(), W, W, im[e]);
    Pose p;
    p.position = Eigen::Vector3f(e == 0 ? -0.032f : 0.032f, 1.45f, 1.2f);
    vt[e].view = make_view(p, Fov{-0.785f, 0.785f, 0.785f, -0.785f});
    vt[e].target = ColorTarget{
        im[e].color, VK_FORMAT_R8G8B8A8_SRGB, W, W, 0, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
  }
  TextPanel p;
  p.lines = {"left hand: -", "right hand: pinching particle 12", "voice: heard \"pin\" -> pin",
             "pinch: nothing within 3 cm of the right hand to pinch"};
  p.version = 7;
  p.head.position = Eigen::Vector3f(0, 1.45f, 1.2f);
  r->set_text_panel(p);
  ASSERT_TRUE(r->render_views(s, vt, 2).ok());
  EXPECT_TRUE(r->last_frame().text_rebuilt);
  ASSERT_TRUE(r->render_views(s, vt, 2).ok());
  EXPECT_FALSE(r->last_frame().text_rebuilt);  // same version: the quads are kept
  p.head.position.x() += 0.1f;                 // the head moved: still the same quads
  r->set_text_panel(p);
  ASSERT_TRUE(r->render_views(s, vt, 2).ok());
  EXPECT_FALSE(r->last_frame().text_rebuilt);
  // Frames with and without the panel alternate (the same quads throughout), so that the load
  // of a shared machine weighs on both alike; wall time and the process's CPU time (lavapipe's
  // threads included) per frame, medians.
  const TextPanel none;
  std::vector<double> wall[2], cpu[2];
  for (int i = 0; i < 40; ++i) {
    const int with = i % 2;
    r->set_text_panel(with ? p : none);
    const double c0 = process_cpu_ms();
    const auto t0 = std::chrono::steady_clock::now();
    ASSERT_TRUE(r->render_views(s, vt, 2).ok());
    wall[with].push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    cpu[with].push_back(process_cpu_ms() - c0);
    EXPECT_FALSE(r->last_frame().text_rebuilt);
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  std::printf(
      "2 x 512^2 views on %s, median per frame without / with the panel: wall %.2f / %.2f ms "
      "(x%.3f), process CPU %.2f / %.2f ms (x%.3f)\n",
      r->device_name().c_str(), median(wall[0]), median(wall[1]), median(wall[1]) / median(wall[0]),
      median(cpu[0]), median(cpu[1]), median(cpu[1]) / median(cpu[0]));
  p.lines.push_back("cut: ignored: stroke has fewer than 2 samples");
  p.version = 8;
  r->set_text_panel(p);
  ASSERT_TRUE(r->render_views(s, vt, 2).ok());
  EXPECT_TRUE(r->last_frame().text_rebuilt);
  r->forget_targets();
  expect_no_validation_messages(*r);
}

}  // namespace
}  // namespace drape::render
