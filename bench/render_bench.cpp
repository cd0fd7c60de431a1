// Renderer benchmark: per-eye frame time at 1024x1024 with a 128x128 cloth draped on the 9AR
// form, drawn into a caller-owned two-layer image exactly as into an XR swapchain (no readback),
// and the CPU time the render thread spends per frame (both eyes). Writes out/bench/render.json.
// Usage: render_bench [frames=20] [size=1024] [sim_seconds=1.0]
#include <time.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <vector>

#include "render/renderer.hpp"
#include "xr_app/scene_file.hpp"

using namespace drape::render;
using namespace drape::app;

namespace {

double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

struct Result {
  double ms_per_eye = 0, cpu_ms_per_frame = 0, build_ms = 0, wait_ms = 0;
  size_t triangles = 0;
};

bool run(const SceneDescription& d, int samples, int frames, uint32_t size, Result& res,
         std::string& device) {
  RendererOptions ro;
  ro.samples = samples;
  auto r = Renderer::create(ro);
  if (!r) {
    std::fprintf(stderr, "render_bench: %s\n", r.error().c_str());
    return false;
  }
  device = (*r)->device_name();
  VulkanContext& ctx = (*r)->context();
  VkImageCreateInfo ii{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ii.imageType = VK_IMAGE_TYPE_2D;
  ii.format = VK_FORMAT_R8G8B8A8_SRGB;
  ii.extent = {size, size, 1};
  ii.mipLevels = 1;
  ii.arrayLayers = 2;
  ii.samples = VK_SAMPLE_COUNT_1_BIT;
  ii.tiling = VK_IMAGE_TILING_OPTIMAL;
  ii.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
  VkImage image = VK_NULL_HANDLE;
  if (vkCreateImage(ctx.device, &ii, nullptr, &image) != VK_SUCCESS) return false;
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(ctx.device, image, &req);
  uint32_t type = 0;
  while (!(req.memoryTypeBits & (1u << type))) ++type;
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = type;
  VkDeviceMemory mem = VK_NULL_HANDLE;
  if (vkAllocateMemory(ctx.device, &ai, nullptr, &mem) != VK_SUCCESS) return false;
  vkBindImageMemory(ctx.device, image, mem, 0);
  std::vector<double> eye_ms, cpu_ms, build, wait;
  const Fov fov{-0.785f, 0.785f, 0.785f, -0.785f};  // 90 degrees, like a headset eye
  for (int f = -2; f < frames; ++f) {               // two warm-up frames
    const double c0 = thread_cpu_ms();
    for (uint32_t eye = 0; eye < 2; ++eye) {
      Pose p;
      p.position = Eigen::Vector3f(eye ? 0.032f : -0.032f, 1.45f, 1.1f);
      p.orientation = Eigen::AngleAxisf(-0.3f, Eigen::Vector3f::UnitX());
      const auto t0 = std::chrono::steady_clock::now();
      const Status s = (*r)->render(d.snapshot, make_view(p, fov),
                                    ColorTarget{image, ii.format, size, size, eye}, d.options);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      if (!s) {
        std::fprintf(stderr, "render_bench: %s\n", s.error.c_str());
        return false;
      }
      if (f >= 0) {
        eye_ms.push_back(ms);
        build.push_back((*r)->last_frame().build_ms);
        wait.push_back((*r)->last_frame().wait_ms);
      }
    }
    if (f >= 0) cpu_ms.push_back(thread_cpu_ms() - c0);
  }
  res.ms_per_eye = median(eye_ms);
  res.cpu_ms_per_frame = median(cpu_ms);
  res.build_ms = median(build);
  res.wait_ms = median(wait);
  res.triangles = (*r)->last_frame().triangles;
  (*r)->forget_targets();
  vkDestroyImage(ctx.device, image, nullptr);
  vkFreeMemory(ctx.device, mem, nullptr);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 20;
  uint32_t size = 1024;
  double sim_seconds = 1.0;
  CLI::App app{
      "Renderer benchmark: per-eye frame time and render CPU time (out/bench/render.json)."};
  app.option_defaults()->always_capture_default();
  app.add_option("frames", frames, "frames timed per MSAA setting")->check(CLI::Range(1, 100000));
  app.add_option("size", size, "eye image size (pixels)")->check(CLI::Range(16, 8192));
  app.add_option("sim_seconds", sim_seconds, "seconds the drape is simulated before drawing")
      ->check(CLI::Range(0.0, 600.0));
  CLI11_PARSE(app, argc, argv);
  auto scene = default_scene(sim_seconds, "xpbd", 128);
  if (!scene) {
    std::fprintf(stderr, "render_bench: %s\n", scene.error().c_str());
    return 1;
  }
  Result r1, r4;
  std::string device;
  if (!run(*scene, 1, frames, size, r1, device) || !run(*scene, 4, frames, size, r4, device))
    return 1;
  std::printf("\nrenderer, %ux%u per eye, 128x128 cloth + 9AR form, device: %s, %d frames\n", size,
              size, device.c_str(), frames);
  std::printf("%-12s %12s %16s %12s %12s %10s\n", "MSAA", "ms/eye", "render CPU ms/fr", "build ms",
              "wait ms", "triangles");
  for (const auto& [name, r] : {std::pair{"1x", r1}, std::pair{"4x", r4}})
    std::printf("%-12s %12.2f %16.2f %12.2f %12.2f %10zu\n", name, r.ms_per_eye, r.cpu_ms_per_frame,
                r.build_ms, r.wait_ms, r.triangles);
  std::printf("ratio 4x/1x ms/eye: %.2f\n", r4.ms_per_eye / std::max(r1.ms_per_eye, 1e-9));
  std::filesystem::create_directories("out/bench");
  std::ofstream js("out/bench/render.json");
  js << "{\n  \"device\": \"" << device << "\",\n  \"size\": " << size
     << ",\n  \"cloth\": \"128x128\",\n"
     << "  \"frames\": " << frames << ",\n  \"ms_per_eye_1024\": " << r1.ms_per_eye
     << ",\n  \"render_cpu_ms\": " << r1.cpu_ms_per_frame
     << ",\n  \"build_ms_per_eye\": " << r1.build_ms << ",\n  \"triangles\": " << r1.triangles
     << ",\n  \"ms_per_eye_1024_msaa4\": " << r4.ms_per_eye
     << ",\n  \"render_cpu_ms_msaa4\": " << r4.cpu_ms_per_frame << "\n}\n";
  std::printf("wrote out/bench/render.json\n");
  return 0;
}
