// Fit map and scene file of the simulated garment (garment_view.hpp).
#include "xr_app/garment_view.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>

#include "sim/form/dress_form.hpp"

#ifdef DRAPE_HAVE_RENDER
#include "render/camera.hpp"
#include "render/image_io.hpp"
#include "render/renderer.hpp"
#include "xr_app/fit_map_legend.hpp"
#endif

namespace drape::app {
namespace {

// Where to look from and at: the cloth's bounding box centre, from `side` (+1 front: the form
// faces +z; -1 back) far enough for its height to fill 90 % of a view of fov_deg.
struct Framing {
  Eigen::Vector3f target, eye;
};
Framing frame_cloth(const sim::Cloth& cloth, int side, float fov_deg) {
  Eigen::Vector3d lo = cloth.state.x.front(), hi = lo;
  for (const sim::Vec3& p : cloth.state.x) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector3f c = (0.5 * (lo + hi)).cast<float>();
  const float h = static_cast<float>(std::max(hi.y() - lo.y(), 0.8 * (hi.x() - lo.x())));
  const float d = 0.5f * h / 0.9f / std::tan(0.5f * fov_deg * 3.14159265f / 180.0f);
  return {c, c + Eigen::Vector3f(0, 0, static_cast<float>(side) * (d + 0.3f))};
}

}  // namespace

#ifdef DRAPE_HAVE_RENDER
std::string write_fit_map(const std::string& png_path, const sim::Cloth& cloth,
                          std::shared_ptr<const sim::DressForm> form, const FitMapOptions& opt) {
  if (cloth.num_vertices() == 0) return png_path + ": no cloth to draw";
  sim::SceneSnapshot snap;
  snap.form = std::move(form);
  for (const sim::Vec3& p : cloth.state.x) snap.positions.push_back(p.cast<float>());
  for (const sim::Vec2& m : cloth.topo.material) snap.material.push_back(m.cast<float>());
  for (const auto& t : cloth.topo.triangles)
    for (int k = 0; k < 3; ++k) snap.indices.push_back(static_cast<uint32_t>(t[k]));
  snap.flags.assign(snap.positions.size(), 0);
  render::RendererOptions ro;
  ro.samples = 4;
  auto r = render::Renderer::create(ro);
  if (!r) return png_path + ": no renderer: " + r.error();
  const int w = opt.tile_width, h = opt.tile_height;
  render::Image out;
  out.width = 2 * w;
  out.height = 2 * h + opt.legend_height;
  out.rgba.assign(static_cast<size_t>(out.width) * out.height * 4, 255);
  const float fov = 30.0f;
  for (int row = 0; row < 2; ++row)
    for (int col = 0; col < 2; ++col) {
      render::DrawOptions d;
      d.colour_map = row == 0 ? render::ColourMap::kEase : render::ColourMap::kStrain;
      d.ease_range = opt.ease_range_m;
      d.strain_range = opt.strain_range;
      d.grain = false;
      d.floor_grid = false;
      d.pattern_panel = false;
      const Framing f = frame_cloth(cloth, col == 0 ? 1 : -1, fov);
      const render::View view = render::look_at(f.eye, f.target, fov * 3.14159265f / 180.0f,
                                                static_cast<float>(w) / static_cast<float>(h));
      auto img = (*r)->render_offscreen(snap, view, w, h, d);
      if (!img) return png_path + ": " + img.error();
      for (int y = 0; y < h; ++y)
        std::copy_n(img->px(0, y), 4 * w,
                    &out.rgba[(static_cast<size_t>(row * h + y) * out.width + col * w) * 4]);
    }
  if (std::string e = draw_fit_map_legend(out, 2 * h, {opt.ease_range_m, opt.strain_range});
      !e.empty())
    return png_path + ": " + e;
  return render::write_png(png_path, out);
}
#else
std::string write_fit_map(const std::string& png_path, const sim::Cloth&,
                          std::shared_ptr<const sim::DressForm>, const FitMapOptions&) {
  return png_path + ": this build has no renderer (DRAPE_BUILD_RENDER=OFF)";
}
#endif

std::string write_garment_scene(const std::string& path, const std::string& gltf_name,
                                const nlohmann::json& form, const sim::DressForm& form_model) {
  const sim::FormLandmarks& lm = form_model.landmarks();
  const sim::Vec2 c = form_model.centre_at(lm.hip_y);
  const double y = 0.5 * (lm.waist_y + lm.hip_y) - 0.15;
  nlohmann::json j;
  j["form"] = form;
  j["cloth"] = {{"mesh", gltf_name}};
  j["camera"] = {
      {"eye", {c.x(), y + 0.1, c.y() + 2.2}}, {"target", {c.x(), y, c.y()}}, {"fov_y_deg", 40}};
  j["options"] = {
      {"colour_map", "ease"}, {"ease_range", 0.02}, {"pattern_panel", false}, {"grain", false}};
  std::ofstream f(path);
  f << j.dump(2) << "\n";
  return f ? std::string() : path + ": write failed";
}

}  // namespace drape::app
