// Glyph atlas (FreeType) and the feedback panel's geometry (see text.hpp).
#include "render/text.hpp"

#include <ft2build.h>
#include FT_FREETYPE_H

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>

namespace drape::render {

namespace {

// The code points of the atlas besides printable ASCII: arrows, degree, middle dot, ellipsis.
constexpr uint32_t kExtra[] = {0x2190, 0x2191, 0x2192, 0x2193, 0x00B0, 0x00B7, 0x2026};

// Decodes UTF-8; malformed bytes become '?'.
std::vector<uint32_t> decode_utf8(const std::string& s) {
  std::vector<uint32_t> out;
  for (size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    int n = c < 0x80 ? 0 : (c >> 5) == 6 ? 1 : (c >> 4) == 14 ? 2 : (c >> 3) == 30 ? 3 : -1;
    if (n < 0 || i + n >= s.size()) {
      out.push_back('?');
      ++i;
      continue;
    }
    uint32_t cp = n == 0 ? c : c & (0x3F >> n);
    for (int k = 1; k <= n; ++k) cp = (cp << 6) | (static_cast<unsigned char>(s[i + k]) & 0x3F);
    out.push_back(cp);
    i += n + 1;
  }
  return out;
}

std::string encode_utf8(const std::vector<uint32_t>& cps) {
  std::string s;
  for (uint32_t cp : cps) {
    if (cp < 0x80) {
      s += static_cast<char>(cp);
    } else if (cp < 0x800) {
      s += static_cast<char>(0xC0 | (cp >> 6));
      s += static_cast<char>(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
      s += static_cast<char>(0xE0 | (cp >> 12));
      s += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      s += static_cast<char>(0x80 | (cp & 0x3F));
    } else {
      s += static_cast<char>(0xF0 | (cp >> 18));
      s += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
      s += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      s += static_cast<char>(0x80 | (cp & 0x3F));
    }
  }
  return s;
}

// Rasterises each code point and packs it in rows into a 1024-pixel-wide atlas (1 px gaps).
void pack_glyphs(FT_Face face, const std::vector<uint32_t>& cps, FontAtlas& a) {
  struct Bitmap {
    uint32_t cp;
    Glyph g;
    std::vector<uint8_t> px;
  };
  std::vector<Bitmap> maps;
  int x = 1, y = 1, row_h = 0;
  a.width = 1024;
  for (uint32_t cp : cps) {
    const FT_UInt index = FT_Get_Char_Index(face, cp);
    if (index == 0 || FT_Load_Glyph(face, index, FT_LOAD_RENDER) != 0) continue;
    const FT_GlyphSlot s = face->glyph;
    Bitmap b{cp, {}, {}};
    b.g.w = static_cast<int>(s->bitmap.width);
    b.g.h = static_cast<int>(s->bitmap.rows);
    b.g.left = s->bitmap_left;
    b.g.top = s->bitmap_top;
    b.g.advance = static_cast<float>(s->advance.x) / 64.0f;
    for (int r = 0; r < b.g.h; ++r)
      for (int c = 0; c < b.g.w; ++c) b.px.push_back(s->bitmap.buffer[r * s->bitmap.pitch + c]);
    if (x + b.g.w + 1 > a.width) {
      x = 1;
      y += row_h + 1;
      row_h = 0;
    }
    b.g.x = x;
    b.g.y = y;
    x += b.g.w + 1;
    row_h = std::max(row_h, b.g.h);
    maps.push_back(std::move(b));
  }
  a.height = 1;
  while (a.height < y + row_h + 1) a.height *= 2;
  a.alpha.assign(static_cast<size_t>(a.width) * a.height, 0);
  for (const auto& b : maps) {
    for (int r = 0; r < b.g.h; ++r)
      std::copy_n(&b.px[static_cast<size_t>(r) * b.g.w], b.g.w,
                  &a.alpha[static_cast<size_t>(b.g.y + r) * a.width + b.g.x]);
    a.glyphs[b.cp] = b.g;
  }
}

}  // namespace

std::string default_font_path() {
  return "/usr/share/fonts/truetype/dejavu/DejaVuSansMono.ttf";
}

sim::Result<FontAtlas> load_font_atlas(const std::string& path, int pixel_size) {
  const std::string where = "font " + path;
  if (!std::filesystem::is_regular_file(path))
    return sim::make_error(where,
                           "no such file (install the Debian package fonts-dejavu-core, "
                           "or give the renderer another TrueType file)");
  if (pixel_size < 4 || pixel_size > 256)
    return sim::make_error(where, "pixel size " + std::to_string(pixel_size) + " out of 4..256");
  FT_Library lib = nullptr;
  if (FT_Init_FreeType(&lib) != 0) return sim::make_error(where, "FreeType did not initialise");
  FT_Face face = nullptr;
  if (FT_New_Face(lib, path.c_str(), 0, &face) != 0) {
    FT_Done_FreeType(lib);
    return sim::make_error(where, "not a font FreeType can read");
  }
  FontAtlas a;
  a.path = path;
  a.pixel_size = pixel_size;
  FT_Set_Pixel_Sizes(face, 0, static_cast<FT_UInt>(pixel_size));
  a.ascent = static_cast<float>(face->size->metrics.ascender) / 64.0f;
  a.line_height = static_cast<float>(face->size->metrics.height) / 64.0f;
  std::vector<uint32_t> cps;
  for (uint32_t c = 32; c < 127; ++c) cps.push_back(c);
  cps.insert(cps.end(), std::begin(kExtra), std::end(kExtra));
  pack_glyphs(face, cps, a);
  FT_Done_Face(face);
  FT_Done_FreeType(lib);
  if (!a.glyphs.count('?') || !a.glyphs.count('A'))
    return sim::make_error(where, "the font lacks the basic Latin letters");
  return a;
}

std::vector<std::string> wrap_lines(const std::vector<std::string>& lines, int columns) {
  std::vector<std::string> out;
  columns = std::max(columns, 8);
  for (const auto& line : lines) {
    std::vector<uint32_t> cps = decode_utf8(line);
    bool first = true;
    do {
      const size_t room = static_cast<size_t>(first ? columns : columns - 2);
      size_t cut = std::min(room, cps.size());
      if (cut < cps.size()) {  // break at the last space that fits, if any
        for (size_t k = cut; k > room / 2; --k)
          if (cps[k] == ' ') {
            cut = k;
            break;
          }
      }
      std::vector<uint32_t> part(cps.begin(), cps.begin() + static_cast<long>(cut));
      out.push_back((first ? "" : "  ") + encode_utf8(part));
      while (cut < cps.size() && cps[cut] == ' ') ++cut;
      cps.erase(cps.begin(), cps.begin() + static_cast<long>(cut));
      first = false;
    } while (!cps.empty());
  }
  return out;
}

namespace {
void add_quad(TextMesh& m, float x0, float y0, float x1, float y1, float u0, float v0, float u1,
              float v1, const float* rgba) {
  const auto base = static_cast<uint32_t>(m.vertices.size());
  const float xs[4] = {x0, x1, x1, x0}, ys[4] = {y0, y0, y1, y1};
  const float us[4] = {u0, u1, u1, u0}, vs[4] = {v0, v0, v1, v1};
  for (int k = 0; k < 4; ++k)
    m.vertices.push_back({{xs[k], ys[k]}, {us[k], vs[k]}, {rgba[0], rgba[1], rgba[2], rgba[3]}});
  for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
}
}  // namespace

TextMesh build_text_panel(const FontAtlas& font, const std::vector<std::string>& lines,
                          const PanelStyle& style) {
  TextMesh m;
  if (lines.empty() || font.glyphs.empty()) return m;
  const float px_advance = font.glyphs.at('M').advance;
  const float inner = style.width - 2 * style.margin;
  // Character size: the style's line height, shrunk when the lines would not fit max_height.
  float lh = style.line_height;
  int columns = static_cast<int>(inner / (lh * px_advance / font.line_height));
  std::vector<std::string> wrapped = wrap_lines(lines, columns);
  const float fit = (style.max_height - 2 * style.margin) / static_cast<float>(wrapped.size());
  if (fit < lh) {
    lh = fit;
    columns = static_cast<int>(inner / (lh * px_advance / font.line_height));
    wrapped = wrap_lines(lines, columns);
    lh = std::min(lh, (style.max_height - 2 * style.margin) / static_cast<float>(wrapped.size()));
  }
  const float s = lh / font.line_height;  // m per atlas pixel
  m.width = style.width;
  m.height = 2 * style.margin + lh * static_cast<float>(wrapped.size());
  add_quad(m, -0.5f * m.width, 0, 0.5f * m.width, -m.height, -1, -1, -1, -1, style.background);
  const float iw = 1.0f / static_cast<float>(font.width),
              ih = 1.0f / static_cast<float>(font.height);
  for (size_t row = 0; row < wrapped.size(); ++row) {
    float pen = -0.5f * inner;
    const float baseline = -style.margin - lh * static_cast<float>(row) - font.ascent * s;
    for (uint32_t cp : decode_utf8(wrapped[row])) {
      auto it = font.glyphs.find(cp);
      if (it == font.glyphs.end()) it = font.glyphs.find('?');
      const Glyph& g = it->second;
      if (g.w > 0 && g.h > 0) {
        const float x0 = pen + g.left * s, y0 = baseline + g.top * s;
        add_quad(m, x0, y0, x0 + g.w * s, y0 - g.h * s, g.x * iw, g.y * ih, (g.x + g.w) * iw,
                 (g.y + g.h) * ih, style.text);
      }
      pen += g.advance * s;
    }
  }
  return m;
}

PanelStyle scaled(const PanelStyle& s, float k) {
  PanelStyle o = s;
  o.width *= k;
  o.line_height *= k;
  o.max_height *= k;
  o.margin *= k;
  return o;
}

float legible_scale(const PanelStyle& s, float rad_per_pixel, float distance, float min_px) {
  const float px_per_line = std::atan(s.line_height / distance) / rad_per_pixel;
  return std::clamp(min_px / px_per_line, 1.0f, 3.0f);
}

Mat4f head_locked_panel(const Pose& head, float panel_height, float distance, float drop,
                        float max_centre_drop) {
  const Eigen::Matrix3f r = head.orientation.toRotationMatrix();
  const float centre_drop = std::min(drop + 0.5f * panel_height, max_centre_drop);
  const Vec3f centre = head.position + r * Vec3f(0, -centre_drop, -distance);
  const Vec3f top = centre + r.col(1) * (0.5f * panel_height);
  // Facing the eye: the panel's normal (+z) points from its centre to the eye; its x stays the
  // head's right, so the panel turns about the head's horizontal axis only.
  const Vec3f z = (head.position - centre).normalized();
  const Vec3f x = (r.col(0) - r.col(0).dot(z) * z).normalized();
  const Vec3f y = z.cross(x);
  // The origin of the panel's plane is the middle of its top edge.
  Mat4f m = Mat4f::Identity();
  m.block<3, 1>(0, 0) = x;
  m.block<3, 1>(0, 1) = y;
  m.block<3, 1>(0, 2) = z;
  m.block<3, 1>(0, 3) = top;
  return m;
}

Pose pose_of(const View& view) {
  Pose p;
  const Eigen::Matrix3f r = view.view.block<3, 3>(0, 0).transpose();
  p.orientation = Eigen::Quaternionf(r);
  p.position = view.eye;
  return p;
}

}  // namespace drape::render
