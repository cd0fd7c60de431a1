// `drape render`: renders a scene headless to PNG (docs, tests), optionally also in a mirror
// window. With no --scene it renders the default scene (muslin draped on the 9AR form).
#ifdef DRAPE_HAVE_RENDER

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "render/image_io.hpp"
#include "render/mirror_window.hpp"
#include "render/renderer.hpp"
#include "xr_app/command.hpp"
#include "xr_app/scene_file.hpp"

namespace {

using namespace drape::render;
using namespace drape::app;

void usage() {
  std::fprintf(
      stderr,
      "usage: drape render [--scene FILE] --out shot.png [--size WxH] [options]\n"
      "  --scene FILE        scene JSON (docs/rendering.md); default: muslin on the 9AR form\n"
      "  --out FILE          PNG to write (default shot.png)\n"
      "  --size WxH          image size (default 1024x1024)\n"
      "  --samples N         MSAA samples (default from the scene, 4)\n"
      "  --colour-map M      none | strain | ease\n"
      "  --eye X,Y,Z         camera position (look-at camera)\n"
      "  --target X,Y,Z      camera target\n"
      "  --sim-seconds S     default scene: simulated draping time (default 2.5)\n"
      "  --solver NAME       default scene: solver (default xpbd)\n"
      "  --window [N]        also show N frames (default: until closed) in a mirror window\n"
      "  --validation        enable the Vulkan validation layer (counts messages)\n");
}

bool parse_vec(const char* s, Eigen::Vector3f& v) {
  return std::sscanf(s, "%f,%f,%f", &v.x(), &v.y(), &v.z()) == 3;
}

int run_render(int argc, char** argv) {
  std::string scene_path, out = "shot.png", cmap, solver = "xpbd";
  int w = 1024, h = 1024, samples = 0, window_frames = -1;
  double sim_seconds = 2.5;
  bool validation = false;
  Eigen::Vector3f eye, target;
  bool have_eye = false, have_target = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "drape render: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      usage();
      return 0;
    } else if (a == "--scene") {
      scene_path = next();
    } else if (a == "--out") {
      out = next();
    } else if (a == "--size") {
      if (std::sscanf(next(), "%dx%d", &w, &h) != 2 || w <= 0 || h <= 0 || w > 16384 || h > 16384) {
        std::fprintf(stderr, "drape render: --size expects WxH (1..16384)\n");
        return 2;
      }
    } else if (a == "--samples") {
      samples = std::atoi(next());
    } else if (a == "--colour-map" || a == "--color-map") {
      cmap = next();
    } else if (a == "--eye") {
      have_eye = parse_vec(next(), eye);
      if (!have_eye) return std::fprintf(stderr, "drape render: --eye expects X,Y,Z\n"), 2;
    } else if (a == "--target") {
      have_target = parse_vec(next(), target);
      if (!have_target) return std::fprintf(stderr, "drape render: --target expects X,Y,Z\n"), 2;
    } else if (a == "--sim-seconds") {
      sim_seconds = std::atof(next());
    } else if (a == "--solver") {
      solver = next();
    } else if (a == "--window") {
      window_frames = 0;
      if (i + 1 < argc && argv[i + 1][0] != '-') window_frames = std::atoi(argv[++i]);
    } else if (a == "--validation") {
      validation = true;
    } else {
      std::fprintf(stderr, "drape render: unknown option '%s'\n", a.c_str());
      usage();
      return 2;
    }
  }
  auto scene = scene_path.empty() ? default_scene(sim_seconds, solver) : load_scene(scene_path);
  if (!scene) {
    std::fprintf(stderr, "drape render: %s\n", scene.error().c_str());
    return 1;
  }
  SceneDescription& d = *scene;
  if (!cmap.empty()) {
    if (cmap == "none")
      d.options.colour_map = ColourMap::kNone;
    else if (cmap == "strain")
      d.options.colour_map = ColourMap::kStrain;
    else if (cmap == "ease")
      d.options.colour_map = ColourMap::kEase;
    else
      return std::fprintf(stderr, "drape render: --colour-map: none, strain or ease\n"), 2;
  }
  if (have_eye) d.camera.eye = eye, d.camera.xr_fov.reset();
  if (have_target) d.camera.target = target, d.camera.xr_fov.reset();

  RendererOptions ro;
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
