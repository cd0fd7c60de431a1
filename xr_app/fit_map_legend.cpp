// The fit map's legend: colour bars and their labels (fit_map_legend.hpp).
#include "xr_app/fit_map_legend.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "render/text.hpp"

namespace drape::app {
namespace {

using Rgb = std::array<float, 3>;  // linear

Rgb mix(const Rgb& a, const Rgb& b, float t) {
  return {a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t};
}

// Linear -> sRGB bytes (the shader's to_srgb).
void to_srgb(const Rgb& c, unsigned char rgb[3]) {
  for (int k = 0; k < 3; ++k) {
    const float v = std::clamp(c[k], 0.0f, 1.0f);
    const float s = v < 0.0031308f ? v * 12.92f : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
    rgb[k] = static_cast<unsigned char>(std::lround(s * 255.0f));
  }
}

void put(render::Image& img, int x, int y, const unsigned char rgb[3], float a = 1.0f) {
  if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
  uint8_t* p = &img.rgba[(static_cast<size_t>(y) * img.width + x) * 4];
  for (int k = 0; k < 3; ++k)
    p[k] = static_cast<uint8_t>(std::lround(p[k] + (rgb[k] - p[k]) * std::clamp(a, 0.0f, 1.0f)));
  p[3] = 255;
}

// `text` with its baseline at y, starting at x (centred on x when `centre`).
void text(render::Image& img, const render::FontAtlas& f, const std::string& s, int x, int y,
          bool centre = false) {
  static const unsigned char kInk[3] = {30, 30, 30};
  float width = 0;
  for (char c : s) width += f.glyphs.count(c) ? f.glyphs.at(c).advance : 0;
  float pen = centre ? x - width / 2 : static_cast<float>(x);
  for (char c : s) {
    const auto it = f.glyphs.find(static_cast<unsigned char>(c));
    if (it == f.glyphs.end()) continue;
    const render::Glyph& g = it->second;
    for (int j = 0; j < g.h; ++j)
      for (int i = 0; i < g.w; ++i) {
        const float a = f.alpha[static_cast<size_t>(g.y + j) * f.width + g.x + i] / 255.0f;
        if (a > 0) put(img, static_cast<int>(pen) + g.left + i, y - g.top + j, kInk, a);
      }
    pen += g.advance;
  }
}

// One bar: `title` above, the ramp `colour` over [lo, hi] of the values from x0 to x1, ticks
// and their labels (`ticks` values, printed with `fmt`) below.
struct Bar {
  std::string title;
  float lo, hi;
  void (*colour)(float, unsigned char*);
  bool diverging;
  std::vector<float> ticks;
  const char* fmt;
  bool open_end;  // the last colour stands for the last value or more ("20+")
};

void draw_bar(render::Image& img, const render::FontAtlas& f, const Bar& b, int x0, int x1,
              int y0) {
  const int top = y0 + 34, height = 26;
  text(img, f, b.title, x0, y0 + 24);
  for (int x = x0; x <= x1; ++x) {
    const float t = static_cast<float>(x - x0) / static_cast<float>(x1 - x0);
    unsigned char rgb[3];
    b.colour(b.diverging ? 2 * t - 1 : t, rgb);
    for (int y = top; y < top + height; ++y) put(img, x, y, rgb);
  }
  static const unsigned char kTick[3] = {30, 30, 30};
  for (float v : b.ticks) {
    const int x = x0 + static_cast<int>(std::lround((v - b.lo) / (b.hi - b.lo) * (x1 - x0)));
    for (int y = top + height; y < top + height + 6; ++y) put(img, x, y, kTick);
    char label[32];
    std::snprintf(label, sizeof label, b.fmt, v);
    const std::string shown = std::string(label) + (b.open_end && v == b.ticks.back() ? "+" : "");
    text(img, f, shown, x, top + height + 24, true);
  }
}

}  // namespace

void ease_colour(float s, unsigned char rgb[3]) {
  s = std::clamp(s, 0.0f, 1.0f);
  const Rgb c0{0.85f, 0.10f, 0.08f}, c1{0.95f, 0.85f, 0.20f}, c2{0.20f, 0.70f, 0.30f},
      c3{0.15f, 0.35f, 0.85f};
  const Rgb c = s < 0.33f   ? mix(c0, c1, s / 0.33f)
                : s < 0.66f ? mix(c1, c2, (s - 0.33f) / 0.33f)
                            : mix(c2, c3, (s - 0.66f) / 0.34f);
  to_srgb(c, rgb);
}

void strain_colour(float s, unsigned char rgb[3]) {
  s = std::clamp(s, -1.0f, 1.0f);
  const Rgb white{0.95f, 0.95f, 0.95f}, blue{0.10f, 0.25f, 0.85f}, red{0.85f, 0.10f, 0.08f};
  to_srgb(s < 0 ? mix(white, blue, -s) : mix(white, red, s), rgb);
}

std::string draw_fit_map_legend(render::Image& img, int y0, const LegendRanges& r) {
  auto font = render::load_font_atlas(render::default_font_path(), 18);
  if (!font) return "legend: " + font.error();
  const float ease_mm = r.ease_range_m * 1000, strain_pct = r.strain_range * 100;
  const Bar ease{"ease in mm (top row)",
                 0,
                 ease_mm,
                 ease_colour,
                 false,
                 {0, ease_mm / 4, ease_mm / 2, 3 * ease_mm / 4, ease_mm},
                 "%.0f",
                 true};
  const Bar strain{"strain in % (bottom row)",
                   -strain_pct,
                   strain_pct,
                   strain_colour,
                   true,
                   {-strain_pct, -strain_pct / 2, 0, strain_pct / 2, strain_pct},
                   "%+.1f",
                   false};
  const int half = img.width / 2, margin = 40;
  draw_bar(img, *font, ease, margin, half - margin, y0);
  draw_bar(img, *font, strain, half + margin, img.width - margin, y0);
  return "";
}

}  // namespace drape::app
