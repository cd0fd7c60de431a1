// `drape render`: renders a scene headless to PNG (docs, tests), optionally also in a mirror
// window. With no --scene it renders the default scene (muslin draped on the 9AR form).
#ifdef DRAPE_HAVE_RENDER

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>

#include "render/image_io.hpp"
#include "render/mirror_window.hpp"
#include "render/renderer.hpp"
#include "xr_app/command.hpp"
#include "xr_app/scene_file.hpp"

namespace {

using namespace drape::render;
using namespace drape::app;

// "X,Y,Z" -> a vector; "" when it parses, else what is wrong (a CLI11 check).
std::string check_vec(const std::string& s) {
  Eigen::Vector3f v;
  char tail = 0;
  return std::sscanf(s.c_str(), "%f,%f,%f%c", &v.x(), &v.y(), &v.z(), &tail) == 3
             ? std::string()
             : "expected X,Y,Z (three numbers), got '" + s + "'";
}

bool parse_vec(const std::string& s, Eigen::Vector3f& v) {
  return std::sscanf(s.c_str(), "%f,%f,%f", &v.x(), &v.y(), &v.z()) == 3;
}

int run_render(int argc, char** argv) {
  std::string scene_path, out = "shot.png", cmap, solver = "xpbd", size = "1024x1024", window;
  std::string eye_text, target_text;
  int w = 1024, h = 1024, samples = 0, window_frames = -1;
  double sim_seconds = 2.5;
  bool validation = false;
  Eigen::Vector3f eye, target;
  RendererOptions ro;
  const std::map<std::string, ColourMap> colour_maps = {
      {"none", ColourMap::kNone}, {"strain", ColourMap::kStrain}, {"ease", ColourMap::kEase}};
  CLI::App cli{
      "Renders a scene headless to PNG (default: muslin draped on the 9AR form), optionally\n"
      "also in a mirror window.",
      "drape render"};
  cli.option_defaults()->always_capture_default();
  cli.add_option("--scene", scene_path,
                 "scene JSON (docs/rendering.md); default: muslin on the 9AR form")
      ->type_name("FILE");
  cli.add_option("--out", out, "PNG to write")->type_name("FILE");
  cli.add_option("--size", size, "image size")
      ->type_name("WxH")
      ->check(
          [&](const std::string& s) -> std::string {
            char tail = 0;
            return std::sscanf(s.c_str(), "%dx%d%c", &w, &h, &tail) != 2 || w <= 0 || h <= 0 ||
                           w > 16384 || h > 16384
                       ? "expected WxH, each 1..16384, got '" + s + "'"
                       : std::string();
          },
          "");
  cli.add_option("--samples", samples, "MSAA samples (default from the scene, 4)")
      ->default_str("")
      ->type_name("N")
      ->check(CLI::Range(0, 64));
  cli.add_option("--colour-map,--color-map", cmap, "colour map")
      ->type_name("MAP")
      ->check(CLI::IsMember(colour_maps));
  cli.add_option("--eye", eye_text, "camera position (look-at camera)")
      ->type_name("X,Y,Z")
      ->check(check_vec, "");
  cli.add_option("--target", target_text, "camera target")
      ->type_name("X,Y,Z")
      ->check(check_vec, "");
  cli.add_option("--sim-seconds", sim_seconds, "default scene: simulated draping time (s)")
      ->type_name("S")
      ->check(positive_up_to(60));
  cli.add_option("--solver", solver, "default scene: solver")->type_name("NAME");
  auto* o_window =
      cli.add_option("--window", window,
                     "also show N frames (default: until closed) in a mirror window")
          ->type_name("[N]")
          ->expected(0, 1)
          ->check(
              [](const std::string& s) -> std::string {
                int n = 0;
                char tail = 0;
                return s.empty() || (std::sscanf(s.c_str(), "%d%c", &n, &tail) == 1 && n >= 0)
                           ? std::string()
                           : "expected a number of frames, got '" + s + "'";
              },
              "");
  cli.add_flag("--validation", validation, "enable the Vulkan validation layer (counts messages)");
  cli.add_option("--vk-device", ro.context.device_filter,
                 "use the Vulkan device whose name contains TEXT (default: the best one)")
      ->type_name("TEXT");
  if (int rc = parse_command_line(cli, argc, argv); rc >= 0) return rc;
  const bool have_eye = !eye_text.empty() && parse_vec(eye_text, eye);
  const bool have_target = !target_text.empty() && parse_vec(target_text, target);
  if (o_window->count()) window_frames = window.empty() ? 0 : std::atoi(window.c_str());
  auto scene = scene_path.empty() ? default_scene(sim_seconds, solver) : load_scene(scene_path);
  if (!scene) {
    std::fprintf(stderr, "drape render: %s\n", scene.error().c_str());
    return 1;
  }
  SceneDescription& d = *scene;
  if (!cmap.empty()) d.options.colour_map = colour_maps.at(cmap);
  if (have_eye) d.camera.eye = eye, d.camera.xr_fov.reset();
  if (have_target) d.camera.target = target, d.camera.xr_fov.reset();

  ro.samples = samples > 0 ? samples : d.samples;
  ro.context.validation = validation;
  bool want_window = window_frames >= 0;
  if (want_window) {
    auto exts = MirrorWindow::prepare();
    if (exts) {
      ro.context.instance_extensions = *exts;
      ro.context.swapchain = true;
    } else {
      std::fprintf(stderr, "drape render: %s\n", exts.error().c_str());
      want_window = false;
    }
  }
  auto r = Renderer::create(ro);
  if (!r) {
    std::fprintf(stderr, "drape render: %s\n", r.error().c_str());
    return 1;
  }
  const View view = d.camera.view(w, h);
  auto img = (*r)->render_offscreen(d.snapshot, view, w, h, d.options);
  if (!img) {
    std::fprintf(stderr, "drape render: %s\n", img.error().c_str());
    return 1;
  }
  if (std::string e = write_png(out, *img); !e.empty()) {
    std::fprintf(stderr, "drape render: %s\n", e.c_str());
    return 1;
  }
  const FrameStats& fs = (*r)->last_frame();
  std::printf("wrote %s (%dx%d, %d samples) on %s: %s; %zu triangles, %.1f ms frame\n", out.c_str(),
              w, h, ro.samples, (*r)->device_name().c_str(), d.summary.c_str(), fs.triangles,
              fs.build_ms + fs.submit_ms + fs.wait_ms);
  if (want_window) {
    auto win = MirrorWindow::open(**r, std::min(w, 1024), std::min(h, 1024), "drape render");
    if (!win) {
      std::fprintf(stderr, "drape render: %s\n", win.error().c_str());
    } else {
      for (int f = 0; (window_frames == 0 || f < window_frames) && !(*win)->should_close(); ++f) {
        const View wv = d.camera.view((*win)->width(), std::max((*win)->height(), 1));
        if (Status s = (*win)->show(d.snapshot, wv, d.options); !s) {
          std::fprintf(stderr, "drape render: %s\n", s.error.c_str());
          break;
        }
      }
    }
  }
  if (validation) {
    const ValidationCounts vc = (*r)->validation();
    std::printf("validation: %u errors, %u warnings\n", vc.errors, vc.warnings);
    for (const auto& m : vc.messages) std::printf("  %s\n", m.c_str());
    if (vc.errors) return 1;
  }
  return 0;
}

}  // namespace

DRAPE_COMMAND(render, "render a scene snapshot to PNG (headless; optional mirror window)",
              run_render);

#endif  // DRAPE_HAVE_RENDER
