// CPU-side geometry of a frame: every object of a SceneSnapshot becomes world-space triangles in
// one vertex format (render/shaders/scene.vert), so the whole scene is one pipeline and two draws
// (the static form, the per-frame rest). Pure functions: testable without a GPU.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "sim/core/snapshot.hpp"

namespace drape::sim {
class DressForm;
}

namespace drape::render {

enum class ShadeMode : int { kLit = 0, kForm = 1, kCloth = 2, kUnlit = 3, kFloor = 4 };
enum class ColourMap : int { kNone = 0, kStrain = 1, kEase = 2 };

struct Vertex {
  float pos[3];
  float normal[3];
  float uv[2];     // cloth: material coordinates (m)
  float color[4];  // linear RGB
  float aux[4];    // mode, section centre x, section centre z, colour-map scalar
};
static_assert(sizeof(Vertex) == 16 * sizeof(float));

struct Mesh {
  std::vector<Vertex> vertices;
  std::vector<uint32_t> indices;
  void clear() {
    vertices.clear();
    indices.clear();
  }
};

// A hand drawn from the XR frame's own located pose (XR_EXT_hand_tracking joints or a controller
// grip), not from the snapshot: the user sees the hand where it is in the frame being displayed,
// while the sim's copy of the hand (snapshot.hands) may be a tick or two behind.
struct HandOverlay {
  int id = 1;                                         // 0 left, 1 right
  bool has_joints = false;                            // joints[] valid (26, XrHandJointEXT order)
  std::array<Eigen::Vector3f, 26> joints{};           // stage space (m)
  Eigen::Vector3f pointer = Eigen::Vector3f::Zero();  // where operations act: pinch point / grip
  bool active = false;  // an operation is held (pinch closed, cutting)
};

// The live pattern board's content (the app's, xr_app/app/pattern_board.hpp): each piece of the
// draped cloth flat, in material coordinates (m; u weft, v warp).
struct BoardPiece {
  std::vector<Eigen::Vector2f> outline;  // closed, the last point not repeated
  Eigen::Vector2f grain_a = Eigen::Vector2f::Zero(), grain_b = Eigen::Vector2f::Zero();
  std::vector<Eigen::Vector2f> notches;  // points on the outline (reference lines crossing it)
};
struct PatternBoard {
  std::vector<BoardPiece> pieces;
};

// What to draw and how; everything has a sensible default.
struct DrawOptions {
  ColourMap colour_map = ColourMap::kNone;
  float strain_range = 0.05f;   // |strain| mapped to full colour
  float ease_range = 0.05f;     // ease (m) mapped to the loose end of the ramp
  bool grain = true;            // warp/weft check on the cloth
  float grain_spacing = 0.02f;  // m between grain lines (every 5th warp line is stronger)
  bool floor_grid = true;
  bool pattern_panel = true;
  Eigen::Vector3f panel_centre{0.72f, 1.25f, 0.15f};  // floating pattern panel (stage space)
  float panel_yaw = -0.45f;  // rotation about +y; 0 faces +z (like the form's front)
  float panel_size = 0.5f;   // edge length of the square panel (m)
  // When set, the panel shows this board (outlines, grain lines with arrow heads, notches and a
  // 10 cm scale bar) instead of the snapshot's pattern_outlines.
  std::shared_ptr<const PatternBoard> board;
  float line_half_width = 0.0025f;                             // reference lines on the form (m)
  std::array<float, 4> background{0.55f, 0.60f, 0.68f, 1.0f};  // linear RGB
  std::array<float, 3> cloth_colour{0.92f, 0.89f, 0.80f};      // unbleached muslin
  std::array<float, 3> form_colour{0.62f, 0.52f, 0.40f};       // linen-covered form
  float form_section_spacing = 0.008f;  // decimation of the form's sections for drawing (m)
  // Decimation of the form's 256 angles for drawing: every form_angle_step-th angle (1, 2, 4, 8,
  // 16 or 32; others round down to one of these). The XR app picks both from its eyes' pixel size
  // (form_lod_for_pixels): lavapipe's cost is dominated by vertices, not pixels.
  int form_angle_step = 1;
  // Live hands (see HandOverlay). A hand given here replaces the snapshot's proxy of the same
  // id; the candidate highlight of that hand is joined to its pointer by a thin line.
  std::vector<HandOverlay> hands;
  // Marked points to touch (the app's tracker calibration): unlit spheres of this colour, 1.5 cm
  // in radius, drawn with the hands.
  struct Marker {
    Eigen::Vector3f at = Eigen::Vector3f::Zero();  // stage space (m)
    std::array<float, 3> colour{1.0f, 0.2f, 0.8f};
  };
  std::vector<Marker> markers;
};

// Level of detail of the drawn form for a view whose pixels subtend `rad_per_pixel` (radians):
// grid quads about `quad_px` pixels on a surface 1 m away (the form stands ~1 m from the head),
// sections 8 mm to 30 mm apart, angle step so that a 1.3 m girth keeps that size.
struct FormLod {
  float section_spacing = 0.008f;
  int angle_step = 1;
};
FormLod form_lod_for_pixels(float rad_per_pixel, float quad_px = 8.0f);

// The dress form as a smooth grid of its sections (normals from the grid), capped, in form mode.
// Every opt.form_angle_step-th angle is used. The grid and both caps are wound counter-clockwise
// seen from outside (back faces may be culled).
void append_form(const sim::DressForm& form, float max_section_spacing, const DrawOptions& opt,
                 Mesh& out);
// The cloth (two-sided in the shader) with the snapshot's normals (recomputed here when the
// snapshot has none) and the colour-map scalar per vertex.
void append_cloth(const sim::SceneSnapshot& snap, const DrawOptions& opt, Mesh& out);
// Plates, boxes, spheres, hands, pins, candidates, cut strokes, pattern panel.
void append_decorations(const sim::SceneSnapshot& snap, const DrawOptions& opt, Mesh& out);
// The live hands of DrawOptions::hands: joints as small spheres joined by bones (or a controller
// marker), the pointer as a ring-like sphere (bright when active).
void append_hand_overlays(const sim::SceneSnapshot& snap, const DrawOptions& opt, Mesh& out);
// The floor quad (grid in the shader).
void append_floor(Mesh& out);

// Signed radial distance of p from the form surface (< 0 inside), from the section model only
// (bilinear in height and angle, like sim::DressForm::radius_at); +inf outside its height range.
float form_distance(const sim::DressForm& form, const Eigen::Vector3f& p);
// Area-weighted vertex normals of a triangle mesh.
void vertex_normals(const std::vector<sim::Vec3f>& pos, const std::vector<uint32_t>& idx,
                    std::vector<sim::Vec3f>& normals);

// Per-vertex membrane strain from material coordinates: for each triangle the principal
// stretches of F (material -> 3D), the one furthest from 1 minus 1 (tension > 0, compression
// < 0), averaged over the triangles around a vertex (weighted by material area).
void material_strain(const std::vector<sim::Vec3f>& pos, const std::vector<sim::Vec2f>& material,
                     const std::vector<uint32_t>& idx, std::vector<float>& strain);

// Primitive builders (world space), used above and by tests.
void append_sphere(Mesh& out, const Eigen::Vector3f& c, float r, const std::array<float, 3>& rgb,
                   ShadeMode mode, int slices = 12, int stacks = 8);
void append_box(Mesh& out, const Eigen::Vector3f& c, const Eigen::Vector3f& half,
                const std::array<float, 3>& rgb);
void append_tube(Mesh& out, const Eigen::Vector3f& a, const Eigen::Vector3f& b, float r,
                 const std::array<float, 3>& rgb, ShadeMode mode, int sides = 8);

}  // namespace drape::render
