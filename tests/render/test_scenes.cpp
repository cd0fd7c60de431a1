// Hand-built test scenes (tests/render/test_scenes.hpp).
#include "test_scenes.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "sim/form/dress_form.hpp"

namespace drape::render::test {

std::shared_ptr<const sim::DressForm> analytic_form() {
  const double y0 = 0.60, y1 = 1.34, dy = 0.005;
  const int ns = static_cast<int>(std::lround((y1 - y0) / dy)) + 1;
  std::vector<sim::Vec2> centres(ns, sim::Vec2::Zero());
  std::vector<double> radii(static_cast<size_t>(ns) * sim::DressForm::kAngles);
  for (int j = 0; j < ns; ++j) {
    const double y = y0 + j * dy;
    // Half-width and half-depth: hip 0.17/0.12, waist 0.12/0.09, bust 0.15/0.11, neck 0.06.
    const double t = (y - y0) / (y1 - y0);
    const double a = 0.16 - 0.1 * std::sin(3.1 * t) * t +
                     0.05 * std::exp(-std::pow((y - 1.15) / 0.06, 2)) -
                     0.06 * std::pow(std::max(0.0, (y - 1.22) / 0.12), 2);
    const double b = 0.75 * a;
    for (int n = 0; n < sim::DressForm::kAngles; ++n) {
      const double th = sim::DressForm::theta(n);
      const double bust = y > 1.05 && y < 1.25 ? 0.015 * std::exp(-std::pow((y - 1.15) / 0.04, 2)) *
                                                     std::pow(std::max(0.0, std::cos(th)), 4)
                                               : 0.0;
      radii[static_cast<size_t>(j) * sim::DressForm::kAngles + n] =
          a * b / std::sqrt(std::pow(b * std::sin(th), 2) + std::pow(a * std::cos(th), 2)) + bust;
    }
  }
  sim::FormLandmarks lm;
  lm.bottom_y = y0;
  lm.top_y = y1;
  lm.hip_y = 0.78;
  lm.waist_y = 0.97;
  lm.bust_y = 1.15;
  lm.neck_y = 1.34;
  return std::make_shared<const sim::DressForm>(y0, dy, centres, radii, lm);
}

void add_panel(sim::SceneSnapshot& s, int nx, int ny, float w, float h, float x0, float y0,
               float z0, float fold) {
  const auto base = static_cast<uint32_t>(s.positions.size());
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const float u = w * i / (nx - 1), v = h * j / (ny - 1);
      s.positions.emplace_back(x0 + u, y0 + v, z0 + fold * std::sin(u / w * 4 * 3.14159f));
      s.material.emplace_back(u, v);
    }
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const uint32_t a = base + j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      s.indices.insert(s.indices.end(), {a, b, d, a, d, c});
    }
  s.normals.clear();  // the renderer recomputes them
}

sim::SceneSnapshot decorated_scene() {
  sim::SceneSnapshot s;
  s.form = analytic_form();
  add_panel(s, 40, 40, 0.5f, 0.6f, -0.25f, 0.75f, 0.25f, 0.03f);
  sim::Plate plate;
  plate.centre = sim::Vec3(-0.7, 0.8, 0.0);
  plate.half_x = 0.2;
  plate.half_z = 0.2;
  s.plates.push_back(plate);
  sim::Box box;
  box.centre = sim::Vec3(-0.7, 0.9, 0.0);
  box.half = sim::Vec3(0.08, 0.1, 0.08);
  s.boxes.push_back(box);
  sim::HandProxy h;
  h.id = 1;
  h.tracked = true;
  h.position = sim::Vec3(0.35, 1.2, 0.4);
  h.tip = sim::Vec3(0.3, 1.25, 0.35);
  h.radius = 0.03;
  s.hands.push_back(h);
  s.candidate_vertex[1] = 40 * 30 + 20;
  s.candidate_is_form[0] = true;
  s.candidate_point[0] = sim::Vec3f(0.0f, 0.97f, 0.09f);
  s.pins.push_back(sim::Vec3f(-0.25f, 1.35f, 0.25f));
  s.pins.push_back(sim::Vec3f(0.25f, 1.35f, 0.25f));
  s.cut_strokes.push_back({{-0.1f, 1.0f, 0.3f}, {0.0f, 1.05f, 0.3f}, {0.1f, 1.0f, 0.3f}});
  s.pattern_outlines.push_back({{0, 0}, {0.5f, 0}, {0.5f, 0.6f}, {0.25f, 0.7f}, {0, 0.6f}});
  return s;
}

std::unique_ptr<Renderer> make_test_renderer(int samples) {
  RendererOptions opt;
  opt.context.validation = true;
  opt.context.prefer_cpu = true;  // golden images come from lavapipe
  opt.samples = samples;
  auto r = Renderer::create(opt);
  if (!r) {
    ADD_FAILURE() << r.error();
    return nullptr;
  }
  return std::move(*r);
}

}  // namespace drape::render::test
