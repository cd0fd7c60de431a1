// Text for the in-view feedback panel: a TrueType font rasterised once into a glyph atlas
// (FreeType), and the panel's geometry (a dark rectangle and one textured quad per glyph) built
// on the CPU in the panel's own plane. The renderer draws it with its text pipeline
// (render/shaders/text.*), head-locked at arm's length. Pure functions apart from reading the
// font file: testable without a GPU.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "render/camera.hpp"
#include "sim/core/types.hpp"

namespace drape::render {

// The font of the panel: DejaVu Sans Mono of the Debian package fonts-dejavu-core
// (RendererOptions::font_path names another file).
std::string default_font_path();

struct Glyph {
  int x = 0, y = 0, w = 0, h = 0;  // rectangle in the atlas (px)
  int left = 0, top = 0;           // bitmap offset from the pen (px; top: up from the baseline)
  float advance = 0;               // pen advance (px)
};

// Coverage bitmap (one byte per pixel, rows top to bottom) of the glyphs of printable ASCII and
// a few symbols the app's messages use (arrows, degree, middle dot); other characters are drawn
// as '?'.
struct FontAtlas {
  int width = 0, height = 0;
  std::vector<uint8_t> alpha;
  std::map<uint32_t, Glyph> glyphs;   // by Unicode code point
  int pixel_size = 0;                 // the em size the glyphs were rasterised at (px)
  float ascent = 0, line_height = 0;  // px
  std::string path;                   // the font file
};

// Loads `path` and rasterises the glyphs at `pixel_size`. Errors name the file.
sim::Result<FontAtlas> load_font_atlas(const std::string& path, int pixel_size = 32);

// One vertex of the panel: position in the panel's plane (m; x right, y up, origin at the
// middle of its top edge), atlas coordinates (u < 0: solid colour, no texture), linear RGBA.
struct TextVertex {
  float pos[2];
  float uv[2];
  float color[4];
};

struct TextMesh {
  std::vector<TextVertex> vertices;
  std::vector<uint32_t> indices;
  float width = 0, height = 0;  // the panel's size (m)
};

// How the panel looks: its width and the character height, shrunk so that at most
// max_height is used; lines longer than the panel are wrapped.
struct PanelStyle {
  float width = 0.30f;         // m
  float line_height = 0.014f;  // m (before shrinking)
  float max_height = 0.30f;    // m
  float margin = 0.008f;       // m
  float background[4] = {0.02f, 0.02f, 0.03f, 0.8f};
  float text[4] = {0.95f, 0.95f, 0.90f, 1.0f};
};
// The style with every length times k (a panel k times as large at the same distance).
PanelStyle scaled(const PanelStyle& s, float k);
// How much larger than `s` the panel must be for a line of text to span at least `min_px`
// pixels of a view with `rad_per_pixel` at `distance` (1 when it already does; at most 3). A
// headset's eye (~20 px per degree) reads the panel at its size; a small desk window needs it
// larger.
float legible_scale(const PanelStyle& s, float rad_per_pixel, float distance = 0.55f,
                    float min_px = 12.0f);

// Wraps `lines` to `columns` characters (UTF-8 aware; continuation lines indented by two).
std::vector<std::string> wrap_lines(const std::vector<std::string>& lines, int columns);
// The panel's rectangle and glyph quads for `lines` (none: an empty mesh).
TextMesh build_text_panel(const FontAtlas& font, const std::vector<std::string>& lines,
                          const PanelStyle& style = {});

// Where the panel hangs for a head at `head` (the eye looking down its local -z): the middle of
// its top edge `distance` in front of the eye and `drop` below the line of sight, turned to face
// the eye; a tall panel (the help) is raised so that its centre is at most `max_centre_drop`
// below the line of sight, so it stays in view. Maps the panel's plane (TextVertex::pos, z = 0)
// to stage space.
Mat4f head_locked_panel(const Pose& head, float panel_height, float distance = 0.55f,
                        float drop = 0.12f, float max_centre_drop = 0.24f);
// The pose of a view's eye (the inverse of View::view).
Pose pose_of(const View& view);

}  // namespace drape::render
