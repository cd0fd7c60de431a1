// GPU tests of the renderer on lavapipe: golden images (PSNR >= 40 dB and at most 0.2 % of the
// pixels off by more than 16/255), the projection of known points, the XR handover path, and
// errors (no device, lost device, bad target). Every test ends with zero validation messages.
// Regenerate the golden images with DRAPE_UPDATE_GOLDEN=1 (then look at them!).
#include "render/renderer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>

#include "render/image_io.hpp"
#include "test_scenes.hpp"

namespace drape::render {
namespace {

constexpr double kMinPsnr = 40.0;
constexpr double kMaxFracOff = 0.002;

void expect_no_validation_messages(const Renderer& r) {
  const ValidationCounts v = r.validation();
  EXPECT_EQ(v.errors, 0u);
  EXPECT_EQ(v.warnings, 0u);
  for (const auto& m : v.messages) ADD_FAILURE() << "validation: " << m;
  std::printf("validation messages: %u errors, %u warnings\n", v.errors, v.warnings);
}

void check_golden(const Image& img, const std::string& name) {
  const std::string path = std::string(DRAPE_SOURCE_DIR) + "/tests/render/golden/" + name + ".png";
  if (const char* u = std::getenv("DRAPE_UPDATE_GOLDEN"); u && std::string(u) == "1") {
    ASSERT_EQ(write_png(path, img), "");
    std::printf("golden image written: %s\n", path.c_str());
    return;
  }
  auto golden = read_png(path);
  ASSERT_TRUE(golden.ok()) << golden.error() << " (run with DRAPE_UPDATE_GOLDEN=1 to create it)";
  auto d = compare_images(img, *golden);
  ASSERT_TRUE(d.ok()) << d.error();
  std::printf("%s: PSNR %.2f dB, max channel diff %d, %.4f%% pixels off by > 16\n", name.c_str(),
              d->psnr_db, d->max_abs, 100.0 * d->frac_over_16);
  const bool pass = d->psnr_db >= kMinPsnr && d->frac_over_16 <= kMaxFracOff;
  if (!pass) {
    const std::string out = std::string(DRAPE_BINARY_DIR) + "/render_failures";
    std::filesystem::create_directories(out);
    (void)write_png(out + "/" + name + ".png", img);
    ADD_FAILURE() << "golden mismatch for " << name << "; actual image in " << out;
  }
}

TEST(Renderer, GoldenFormAndCloth) {
  auto r = test::make_test_renderer();
  ASSERT_TRUE(r);
  std::printf("device: %s (cpu %d)\n", r->device_name().c_str(), r->is_cpu_device());
  sim::SceneSnapshot s = test::decorated_scene();
  const View v = look_at({0.6f, 1.4f, 1.7f}, {-0.05f, 1.0f, 0.0f}, 0.75f, 1.0f);
  auto img = r->render_offscreen(s, v, 256, 256);
  ASSERT_TRUE(img.ok()) << img.error();
  check_golden(*img, "form_cloth_256");
  expect_no_validation_messages(*r);
}

TEST(Renderer, GoldenColourMapsAndBackView) {
  auto r = test::make_test_renderer();
  ASSERT_TRUE(r);
  sim::SceneSnapshot s;
  s.form = test::analytic_form();
  // A panel wrapped loosely around the front: ease grows from the centre front outwards.
  const int nx = 30, ny = 20;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const float a = -1.2f + 2.4f * i / (nx - 1), y = 0.85f + 0.3f * j / (ny - 1);
      const float rr = 0.19f + 0.05f * std::abs(a);
      s.positions.emplace_back(rr * std::sin(a), y, rr * std::cos(a));
      s.material.emplace_back(0.6f * i / (nx - 1), 0.3f * j / (ny - 1));
    }
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const uint32_t a = j * nx + i;
      s.indices.insert(s.indices.end(), {a, a + 1, a + nx + 1, a, a + nx + 1, a + nx});
    }
  DrawOptions opt;
  opt.colour_map = ColourMap::kEase;
  opt.ease_range = 0.2f;
  opt.floor_grid = false;
  const View front = look_at({0.0f, 1.1f, 1.3f}, {0.0f, 1.0f, 0.0f}, 0.8f, 1.0f);
  auto ease = r->render_offscreen(s, front, 192, 192, opt);
  ASSERT_TRUE(ease.ok()) << ease.error();
  check_golden(*ease, "ease_map_192");
  // The back of the form with its centre back line (and the cloth's inside from behind).
  opt.colour_map = ColourMap::kStrain;
  const View back = look_at({0.3f, 1.2f, -1.3f}, {0.0f, 1.0f, 0.0f}, 0.8f, 1.0f);
  auto strain = r->render_offscreen(s, back, 192, 192, opt);
  ASSERT_TRUE(strain.ok()) << strain.error();
  check_golden(*strain, "back_strain_192");
  expect_no_validation_messages(*r);
}

// Centroid of the pixels matching a colour predicate.
template <class Pred>
Eigen::Vector2f centroid(const Image& img, Pred pred, int* count) {
  double sx = 0, sy = 0;
  int n = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if (pred(img.px(x, y))) {
        sx += x + 0.5;
        sy += y + 0.5;
        ++n;
      }
  *count = n;
  return n ? Eigen::Vector2f(float(sx / n), float(sy / n)) : Eigen::Vector2f(-1, -1);
}

TEST(Renderer, ProjectionOfKnownPointsWithAsymmetricXrFov) {
  auto r = test::make_test_renderer();
  ASSERT_TRUE(r);
  // An XR eye with an asymmetric field of view, turned 20 degrees left and tilted down.
  Fov fov{-0.75f, 0.55f, 0.50f, -0.80f};
  Pose pose;
  pose.position = Eigen::Vector3f(0.05f, 1.55f, 1.2f);
  pose.orientation = Eigen::AngleAxisf(0.35f, Eigen::Vector3f::UnitY()) *
                     Eigen::AngleAxisf(-0.25f, Eigen::Vector3f::UnitX());
  const View v = make_view(pose, fov);
  sim::SceneSnapshot s;
  s.candidate_is_form[0] = true;  // cyan marker
  s.candidate_point[0] = Eigen::Vector3f(-0.15f, 1.3f, 0.8f);
  s.positions = {{0.1f, 1.0f, 0.6f}};  // green marker on a (triangle-less) cloth vertex
  s.candidate_vertex[1] = 0;
  DrawOptions opt;
  opt.floor_grid = false;
  opt.background = {0, 0, 0, 1};
  const int w = 256, h = 224;
  auto img = r->render_offscreen(s, v, w, h, opt);
  ASSERT_TRUE(img.ok()) << img.error();
  int n_cyan = 0, n_green = 0;
  const auto c_cyan = centroid(
      *img, [](const uint8_t* p) { return p[0] < 120 && p[1] > 200 && p[2] > 200; }, &n_cyan);
  const auto c_green = centroid(
      *img, [](const uint8_t* p) { return p[0] < 120 && p[1] > 200 && p[2] < 150; }, &n_green);
  const auto e_cyan = project_to_pixel(v, s.candidate_point[0], w, h);
  const auto e_green = project_to_pixel(v, s.positions[0], w, h);
  ASSERT_TRUE(e_cyan && e_green);
  std::printf("cyan: %d px, centroid (%.2f, %.2f), expected (%.2f, %.2f)\n", n_cyan, c_cyan.x(),
              c_cyan.y(), e_cyan->x(), e_cyan->y());
  std::printf("green: %d px, centroid (%.2f, %.2f), expected (%.2f, %.2f)\n", n_green, c_green.x(),
              c_green.y(), e_green->x(), e_green->y());
  EXPECT_GT(n_cyan, 12);
  EXPECT_GT(n_green, 12);
  EXPECT_LT((c_cyan - *e_cyan).norm(), 0.5f);
  EXPECT_LT((c_green - *e_green).norm(), 0.5f);
  expect_no_validation_messages(*r);
}

// Simulates the XR path: "the runtime" creates instance and device, the renderer adopts them and
// draws two eyes into layers 0 and 1 of a caller-owned array image (like an XR swapchain image),
// which the test copies out itself: once eye by eye (render), once both eyes in one submission
// (render_views, as the XR app does); the two must be identical.
TEST(Renderer, HandedOverDeviceAndArraySwapchainImage) {
  ContextOptions co;
  co.validation = true;
  co.prefer_cpu = true;
  auto runtime = VulkanContext::create(co);
  ASSERT_TRUE(runtime.ok()) << runtime.error();
  VulkanContext& rt = **runtime;
  const uint32_t w = 64, h = 64;
  VkImageCreateInfo ii{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ii.imageType = VK_IMAGE_TYPE_2D;
  ii.format = VK_FORMAT_R8G8B8A8_UNORM;  // a UNORM swapchain: the shader encodes sRGB
  ii.extent = {w, h, 1};
  ii.mipLevels = 1;
  ii.arrayLayers = 2;
  ii.samples = VK_SAMPLE_COUNT_1_BIT;
  ii.tiling = VK_IMAGE_TILING_OPTIMAL;
  ii.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  VkImage images[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
  VkDeviceMemory mems[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
  VkMemoryRequirements req;
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  uint32_t type = 0;
  for (int k = 0; k < 2; ++k) {
    ASSERT_EQ(vkCreateImage(rt.device, &ii, nullptr, &images[k]), VK_SUCCESS);
    vkGetImageMemoryRequirements(rt.device, images[k], &req);
    type = 0;
    while (!(req.memoryTypeBits & (1u << type))) ++type;
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = type;
    ASSERT_EQ(vkAllocateMemory(rt.device, &ai, nullptr, &mems[k]), VK_SUCCESS);
    vkBindImageMemory(rt.device, images[k], mems[k], 0);
  }
  {
    auto r = Renderer::create_on({rt.instance, rt.physical, rt.device, rt.queue_family, 0});
    ASSERT_TRUE(r.ok()) << r.error();
    sim::SceneSnapshot s = test::decorated_scene();  // form, cloth, decorations: every draw
    ViewTarget vt[2];
    for (uint32_t eye = 0; eye < 2; ++eye) {
      Pose p;
      p.position = Eigen::Vector3f(eye == 0 ? -0.032f : 0.032f, 1.1f, 1.0f);
      vt[eye].view = make_view(p, Fov{-0.6f, 0.6f, 0.6f, -0.6f});
      vt[eye].target =
          ColorTarget{images[0], ii.format, w, h, eye, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
      const Status st = (*r)->render(s, vt[eye].view, vt[eye].target);
      ASSERT_TRUE(st.ok()) << st.error;
      EXPECT_EQ((*r)->last_frame().views, 1);
    }
    for (auto& v : vt) v.target.image = images[1];
    const Status st = (*r)->render_views(s, vt, 2);
    ASSERT_TRUE(st.ok()) << st.error;
    EXPECT_EQ((*r)->last_frame().views, 2);
    EXPECT_FALSE((*r)->last_frame().cloth_rebuilt);  // same snapshot: the cloth is cached
    (*r)->forget_targets();
  }  // the renderer is gone; the runtime's device must still work
  // Copy both layers of both images out with the "runtime's" own commands.
  VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  const VkDeviceSize image_bytes = VkDeviceSize(w) * h * 4 * 2;
  bi.size = 2 * image_bytes;
  bi.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  VkBuffer buf = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateBuffer(rt.device, &bi, nullptr, &buf), VK_SUCCESS);
  vkGetBufferMemoryRequirements(rt.device, buf, &req);
  type = 0;
  while (!(req.memoryTypeBits & (1u << type)) ||
         !(rt.memory.memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT))
    ++type;
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = type;
  VkDeviceMemory bmem = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateMemory(rt.device, &ai, nullptr, &bmem), VK_SUCCESS);
  vkBindBufferMemory(rt.device, buf, bmem, 0);
  VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pi.queueFamilyIndex = rt.queue_family;
  VkCommandPool pool = VK_NULL_HANDLE;
  vkCreateCommandPool(rt.device, &pi, nullptr, &pool);
  VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cai.commandPool = pool;
  cai.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  vkAllocateCommandBuffers(rt.device, &cai, &cmd);
  VkCommandBufferBeginInfo cbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  vkBeginCommandBuffer(cmd, &cbi);
  for (int k = 0; k < 2; ++k) {
    VkBufferImageCopy region{};
    region.bufferOffset = k * image_bytes;
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 2};
    region.imageExtent = {w, h, 1};
    vkCmdCopyImageToBuffer(cmd, images[k], VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buf, 1, &region);
  }
  VkBufferMemoryBarrier bar{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
  bar.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  bar.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  bar.srcQueueFamilyIndex = bar.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  bar.buffer = buf;
  bar.size = VK_WHOLE_SIZE;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0,
                       nullptr, 1, &bar, 0, nullptr);
  vkEndCommandBuffer(cmd);
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  ASSERT_EQ(vkQueueSubmit(rt.queue, 1, &si, VK_NULL_HANDLE), VK_SUCCESS);
  vkQueueWaitIdle(rt.queue);
  void* mapped = nullptr;
  vkMapMemory(rt.device, bmem, 0, VK_WHOLE_SIZE, 0, &mapped);
  const auto* px = static_cast<const uint8_t*>(mapped);
  // Both eyes drew the form (not only the background) and they differ (parallax).
  int form_px[2] = {0, 0}, differ = 0;
  for (uint32_t i = 0; i < w * h; ++i) {
    for (int e = 0; e < 2; ++e) {
      const uint8_t* p = px + (size_t(e) * w * h + i) * 4;
      form_px[e] += p[0] > p[2] + 20;  // warm form colour vs. the blue-grey background
    }
    differ += std::abs(int(px[i * 4]) - int(px[(w * h + i) * 4])) > 8;
  }
  // render_views (both eyes, one submission) == render per eye, byte for byte.
  int max_diff = 0;
  for (VkDeviceSize i = 0; i < image_bytes; ++i)
    max_diff = std::max(max_diff, std::abs(int(px[i]) - int(px[image_bytes + i])));
  std::printf(
      "form pixels: left %d right %d; pixels that differ: %d; render_views vs render: max "
      "channel difference %d\n",
      form_px[0], form_px[1], differ, max_diff);
  EXPECT_GT(form_px[0], 100);  // (the cloth hides part of the form)
  EXPECT_GT(form_px[1], 100);
  EXPECT_GT(differ, 20);
  EXPECT_EQ(max_diff, 0);
  vkUnmapMemory(rt.device, bmem);
  vkDestroyCommandPool(rt.device, pool, nullptr);
  vkDestroyBuffer(rt.device, buf, nullptr);
  vkFreeMemory(rt.device, bmem, nullptr);
  for (int k = 0; k < 2; ++k) {
    vkDestroyImage(rt.device, images[k], nullptr);
    vkFreeMemory(rt.device, mems[k], nullptr);
  }
  const ValidationCounts vc = rt.validation();
  EXPECT_EQ(vc.errors + vc.warnings, 0u);
  for (const auto& m : vc.messages) ADD_FAILURE() << "validation: " << m;
}

// The cloth's vertices are cached between frames: an unchanged snapshot is not rebuilt, a moved,
// re-coloured or re-meshed cloth is, and the image always equals a fresh renderer's.
TEST(Renderer, ClothCacheFollowsTheSnapshot) {
  auto r = test::make_test_renderer();
  auto fresh = test::make_test_renderer();
  ASSERT_TRUE(r && fresh);
  sim::SceneSnapshot s = test::decorated_scene();
  vertex_normals(s.positions, s.indices, s.normals);  // as the sim publishes them
  Pose p;
  p.position = Eigen::Vector3f(0.1f, 1.1f, 1.2f);
  const View v = make_view(p, Fov{-0.5f, 0.5f, 0.5f, -0.5f});
  auto max_diff = [](const Image& a, const Image& b) {
    int m = 0;
    for (size_t i = 0; i < a.rgba.size(); ++i)
      m = std::max(m, std::abs(int(a.rgba[i]) - int(b.rgba[i])));
    return m;
  };
  auto first = r->render_offscreen(s, v, 96, 96);
  ASSERT_TRUE(first.ok()) << first.error();
  EXPECT_TRUE(r->last_frame().cloth_rebuilt);
  auto again = r->render_offscreen(s, v, 96, 96);
  ASSERT_TRUE(again.ok());
  EXPECT_FALSE(r->last_frame().cloth_rebuilt);
  EXPECT_EQ(max_diff(*first, *again), 0);
  struct Change {
    const char* what;
    std::function<void(sim::SceneSnapshot&, DrawOptions&)> apply;
  };
  const Change changes[] = {
      {"moved", [](sim::SceneSnapshot& x, DrawOptions&) { x.positions[5].z() += 0.05f; }},
      {"normals", [](sim::SceneSnapshot& x, DrawOptions&) { x.normals[7] = -x.normals[7]; }},
      {"re-meshed",
       [](sim::SceneSnapshot& x, DrawOptions&) { x.indices.resize(x.indices.size() / 2); }},
      {"colour",
       [](sim::SceneSnapshot&, DrawOptions& o) {
         o.cloth_colour = {0.2f, 0.3f, 0.9f};
       }},
      {"strain map",
       [](sim::SceneSnapshot&, DrawOptions& o) { o.colour_map = ColourMap::kStrain; }},
  };
  DrawOptions opt;
  for (const auto& c : changes) {
    auto before = r->render_offscreen(s, v, 96, 96, opt);
    ASSERT_TRUE(before.ok());
    c.apply(s, opt);
    auto cached = r->render_offscreen(s, v, 96, 96, opt);
    ASSERT_TRUE(cached.ok());
    EXPECT_TRUE(r->last_frame().cloth_rebuilt) << c.what;
    auto ref = fresh->render_offscreen(s, v, 96, 96, opt);
    ASSERT_TRUE(ref.ok());
    std::printf("%s: image vs before %d, vs a fresh renderer %d (max channel difference)\n", c.what,
                max_diff(*before, *cached), max_diff(*cached, *ref));
    EXPECT_GT(max_diff(*before, *cached), 0) << c.what;
    EXPECT_EQ(max_diff(*cached, *ref), 0) << c.what;
  }
  expect_no_validation_messages(*r);
}

TEST(Renderer, MsaaOffscreenMatchesSingleSampleBroadly) {
  auto r1 = test::make_test_renderer(1);
  auto r4 = test::make_test_renderer(4);
  ASSERT_TRUE(r1 && r4);
  sim::SceneSnapshot s = test::decorated_scene();
  const View v = look_at({0.6f, 1.4f, 1.7f}, {-0.05f, 1.0f, 0.0f}, 0.75f, 1.0f);
  auto a = r1->render_offscreen(s, v, 96, 96);
  auto b = r4->render_offscreen(s, v, 96, 96);
  ASSERT_TRUE(a.ok() && b.ok());
  auto d = compare_images(*a, *b);
  ASSERT_TRUE(d.ok());
  std::printf("1x vs 4x MSAA: PSNR %.2f dB\n", d->psnr_db);
  EXPECT_GT(d->psnr_db, 20.0);    // same picture
  EXPECT_LT(d->psnr_db, 1000.0);  // but edges differ (MSAA really on)
  expect_no_validation_messages(*r1);
  expect_no_validation_messages(*r4);
}

TEST(Renderer, LostDeviceIsAnErrorNotACrash) {
  auto r = test::make_test_renderer();
  ASSERT_TRUE(r);
  r->simulate_device_lost();
  sim::SceneSnapshot s = test::decorated_scene();
  auto img = r->render_offscreen(s, look_at({0, 1, 2}, {0, 1, 0}, 0.8f, 1), 32, 32);
  ASSERT_FALSE(img.ok());
  EXPECT_NE(img.error().find("lost"), std::string::npos) << img.error();
  EXPECT_TRUE(r->device_lost());
}

TEST(Renderer, BadTargetsAreErrors) {
  auto r = test::make_test_renderer();
  ASSERT_TRUE(r);
  sim::SceneSnapshot s;
  const View v = look_at({0, 1, 2}, {0, 1, 0}, 0.8f, 1);
  auto img = r->render_offscreen(s, v, 0, 10);
  ASSERT_FALSE(img.ok());
  EXPECT_NE(img.error().find("out of range"), std::string::npos) << img.error();
  const Status st = r->render(s, v, ColorTarget{});
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.error.find("null"), std::string::npos) << st.error;
  // Malformed snapshot (indices out of range, normals of the wrong size): drawn without them.
  s.positions = {{0, 1, 0}, {0.1f, 1, 0}, {0, 1.1f, 0}};
  s.indices = {0, 1, 7, 0, 1, 2};
  s.normals = {{0, 0, 1}};
  auto ok = r->render_offscreen(s, v, 32, 32);
  EXPECT_TRUE(ok.ok()) << ok.error();
  expect_no_validation_messages(*r);
}

TEST(Renderer, NoMatchingDeviceIsAClearError) {
  RendererOptions opt;
  opt.context.device_filter = "no-such-gpu-anywhere";
  auto r = Renderer::create(opt);
  ASSERT_FALSE(r.ok());
  std::printf("error: %s\n", r.error().c_str());
  EXPECT_NE(r.error().find("no suitable device"), std::string::npos);
}

TEST(Renderer, NoVulkanDriverIsAClearError) {
  // Point the loader at a driver manifest that does not exist: no device at all.
  const char* old = std::getenv("VK_ICD_FILENAMES");
  const std::string saved = old ? old : "";
  setenv("VK_ICD_FILENAMES", "/nonexistent/drape_no_driver.json", 1);
  auto r = Renderer::create({});
  if (old)
    setenv("VK_ICD_FILENAMES", saved.c_str(), 1);
  else
    unsetenv("VK_ICD_FILENAMES");
  ASSERT_FALSE(r.ok());
  std::printf("error: %s\n", r.error().c_str());
  EXPECT_NE(r.error().find("vulkan: no Vulkan"), std::string::npos) << r.error();
}

}  // namespace
}  // namespace drape::render
