// The dress form as a section model: horizontal sections at uniform heights, each
// with 256 radii r(section j, angle n) around its own centre, plus reference lines.
//
// Frame (stage space): y up, floor at y = 0, the form stands at the origin and its centre
// front faces +z. The section angle theta is measured from centre front (+z) toward the form's
// LEFT side (+x): the surface point of angle theta is centre + r * (sin theta, 0, cos theta).
// So theta = 0 centre front, pi/2 left side line, pi centre back, 3pi/2 right side line
// (the form's own left/right, as a person wearing it).
#pragma once

#include <array>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "sim/core/types.hpp"

namespace drape::sim {

struct TriMesh;  // sim/core/mesh.hpp

// Body measurements for a parametric form (metres). Girths are tape measures around the section.
struct FormMeasurements {
  std::string size = "9AR";
  double bust_girth = 0.83;
  double waist_girth = 0.64;
  double hip_girth = 0.91;
  double height = 1.58;       // the person's height
  double bust_height = 1.15;  // above the floor
  double waist_height = 0.97;
  double hip_height = 0.78;     // waist - 0.19
  double neck_height = 1.34;    // base of the neck (top of the torso)
  double bottom_height = 0.60;  // bottom of the form (upper thigh)
  // Width/depth of the sections (method digest: ~1.3 at bust and waist, 1.4 at hip).
  double bust_aspect = 1.3, waist_aspect = 1.3, hip_aspect = 1.4;
};

// The measurements of a standard size ("7AR", "9AR", "11AR", "13AR"): read from
// `forms_dir`/<size>.json (the assets/forms/ directory, which the caller finds) when that file
// exists, else the built-in copy of assets/forms/ (a test checks that both agree).
Result<FormMeasurements> measurements_for_size(const std::string& size,
                                               const std::filesystem::path& forms_dir = {});
// Measurements from a JSON file (fields as above, in metres); errors name the file and field.
Result<FormMeasurements> load_measurements(const std::string& path);
// The same from JSON text; `source` names the origin in error messages.
Result<FormMeasurements> parse_measurements(const std::string& json_text,
                                            const std::string& source);

// How to read a scanned or modelled form from a mesh file.
struct MeshImportOptions {
  enum class Units { kAuto, kMetres, kCentimetres, kMillimetres, kInches };
  enum class UpAxis { kAuto, kY, kZ, kX, kNegY, kNegZ, kNegX };
  Units units = Units::kAuto;
  UpAxis up = UpAxis::kAuto;
  bool front_auto = true;           // detect centre front (bust protrudes); else front_axis is used
  Vec3 front_axis{0, 0, 1};         // in the file's frame after the up-axis change
  double section_spacing = 0.0025;  // m between sections
  // Height of the form's bottom in stage space (m). NaN (default): keep the file's height
  // (after units and up axis) when the whole form is above the floor, else put the bottom at
  // 0.60 m (the standard forms' bottom height). docs/dress-form.md.
  double bottom_y = std::numeric_limits<double>::quiet_NaN();
  // Move the form horizontally so its mean section centre is on the vertical axis (x = z = 0).
  bool centre_on_axis = true;
};

// What from_mesh detected (for reports).
struct MeshImportInfo {
  double scale = 1.0;  // file units -> metres
  std::string units;   // "m", "cm", "mm", "in"
  std::string up;      // "+y", "+z", ... (the file's axis that became +y)
  bool units_detected = false, up_detected = false, front_detected = false;
  double front_angle = 0.0;  // rotation about +y applied to bring centre front to +z
  double lift = 0.0;         // vertical translation applied (m)
  int triangles = 0;
  int filled_rays = 0;  // rays that missed and were filled from neighbours
};

// Where the reference lines and landmarks are.
struct FormLandmarks {
  double bottom_y = 0, top_y = 0;             // extent of the section model
  double hip_y = 0, waist_y = 0, bust_y = 0;  // heights of the horizontal reference lines
  double neck_y = 0;
  // Upper body (the bodice's lines): the armpit, where the side seam ends and the armhole
  // begins, and the shoulder point's height (the widest section above the bust, where the
  // shoulder seam down the side line from the neck ends). A parametric form places them from
  // its heights (form_parametric.cpp); a scanned one in the same proportions between bust and
  // neck.
  double armpit_y = 0, shoulder_y = 0;
  double centre_front_theta = 0.0;  // always 0 by construction
  double centre_back_theta = 3.14159265358979323846;
  double left_side_theta = 3.14159265358979323846 / 2;       // side lines (may differ from pi/2
  double right_side_theta = 3 * 3.14159265358979323846 / 2;  // on an asymmetric scan)
};

// The armpit and shoulder heights as fractions of the bust-to-neck height (FormLandmarks): the
// armpit this far above the bust, the shoulder point this far below the neck.
inline constexpr double kArmpitAboveBust = 0.15;
inline constexpr double kShoulderBelowNeck = 0.29;

class DressForm {
 public:
  static constexpr int kAngles = 256;

  DressForm() = default;
  // Builds a form from radii: radii[j * kAngles + n]; section j at height y0 + j * dy.
  DressForm(double y0, double dy, std::vector<Vec2> centres, std::vector<double> radii,
            FormLandmarks landmarks);

  static Result<DressForm> from_measurements(const FormMeasurements& m,
                                             double section_spacing = 0.0025);
  // A form resampled from a mesh in memory (`name` appears in errors; a file is read by
  // form_from_mesh_file in sim/io/mesh_io.hpp); `info` (optional) receives what was detected.
  static Result<DressForm> from_triangles(const TriMesh& mesh, const MeshImportOptions& opt,
                                          const std::string& name, MeshImportInfo* info = nullptr);

  int num_sections() const { return num_sections_; }
  double section_y(int j) const { return y0_ + dy_ * j; }
  double section_spacing() const { return dy_; }
  const Vec2& centre(int j) const { return centres_[j]; }  // (x, z) of the section centre
  double radius(int j, int n) const { return radii_[static_cast<size_t>(j) * kAngles + n]; }
  static double theta(int n) { return 2.0 * 3.14159265358979323846 * n / kAngles; }
  static Vec3 direction(double theta);  // (sin theta, 0, cos theta)
  Vec3 point(int j, int n) const;       // surface sample of section j, angle n

  double min_y() const { return y0_; }
  double max_y() const { return y0_ + dy_ * (num_sections_ - 1); }
  // A bound on |grad F| over the whole form within reach of its surface (F = rho - r, the
  // radial excess; per section in normal_distance_within): a point where
  // normal_distance_within(p) = d >= 0 is at least d / max_gradient() - s from every point
  // where it is below s (within the height range).
  double max_gradient() const { return max_gradient_all_; }
  const FormLandmarks& landmarks() const { return landmarks_; }

  // Continuous surface: bilinear in (height, angle) between the four nearest samples
  // (method 2.2). Heights outside [min_y, max_y] clamp to the end sections.
  double radius_at(double y, double theta) const;
  Vec2 centre_at(double y) const;
  Vec3 surface_at(double y, double theta) const;
  // Tape-measure girth at height y: perimeter of the interpolated section.
  double girth_at(double y) const;

  // O(1) collision by section lookup: if p is closer to the surface than `offset` along the
  // surface's normal (normal_distance_within), moves it along that normal to the offset and
  // returns the penetration depth (> 0); else returns 0 and leaves p. Deeper than
  // kNormalPushDepth (a point that tunnelled in), or in a concave crease where steps along the
  // normal do not settle, radially instead (push_radially; it then returns the radial depth,
  // 0 when the point is radially clear). Points outside the form's height range are untouched.
  double push_outside(Vec3& p, double offset) const;
  static constexpr double kNormalPushDepth = 0.02;  // m
  static constexpr double kPushTolerance = 1e-7;    // m, on the distance along the normal
  // Radial push-out: to surface + offset along the horizontal from the section's centre.
  double push_radially(Vec3& p, double offset) const;
  // Signed radial distance of p from the surface (< 0 inside); +inf outside the height range.
  double signed_distance(const Vec3& p) const;
  // Contact test against the surface's own normal. With F = rho - r(theta, y) the radial
  // distance (rho from the section centre at p.y()), returns F / |g| (the distance to the
  // surface along its normal, to first order) and sets `normal` to g / |g|, where g is grad F
  // with the radius's slopes taken as central differences at the samples and interpolated
  // (a normal continuous across the bilinear cells' edges, where grad F itself jumps): outward,
  // leaning up where the radius shrinks with height (shoulders, above the bust), down where it
  // grows (under the bust, the hips), and sideways where it changes with the angle. The radial
  // direction alone gives a vertical plane on a slope, which carries no weight: a cloth resting
  // there slid down it between contact detections and was pushed out at the next one (a
  // ratchet that kept a settled drape creeping). Values >= reach
  // may be a lower bound (the widest radius of the two sections and a per-cell bound on |g|,
  // without the angle lookup: atan2 and the interpolation, most of the cost); +inf outside the
  // height range or on the axis (normal untouched then).
  double normal_distance_within(const Vec3& p, double reach, Vec3* normal) const;

  // The form as a closed triangle mesh (sections x angles, capped), for rendering and export.
  TriMesh to_mesh() const;

 private:
  double y0_ = 0, dy_ = 0;
  int num_sections_ = 0;
  std::vector<Vec2> centres_;
  std::vector<double> radii_;
  std::vector<double> max_radius_;  // per section, over its angles
  // Per cell between sections j and j + 1: an upper bound of |grad F| within it (its radial
  // slopes in height and angle and its centre's drift; normal_distance_within).
  std::vector<double> max_gradient_;
  double max_gradient_all_ = 1.0;
  // Radius at angle th and centre between sections j and j + 1 at fraction t (located once by
  // the callers: radius_at, centre_at, push_outside, signed_distance).
  double radius_in(int j, double t, double th) const;
  Vec2 centre_in(int j, double t) const;
  // The cell (j, t) of height y, and p's horizontal offset (dx, dz) from the centre there;
  // false outside the form's height range (or NaN): the shared lookup of push_radially,
  // signed_distance and normal_distance_within.
  bool section_of(const Vec3& p, int& j, double& t, double& dx, double& dz) const;
  // Central-difference slopes at sample (j, n): dr/dy, dr/dtheta, and the centre's dc/dy
  // (one-sided at the end sections); tabulated once by the constructor in slopes_ (dr/dy,
  // dr/dtheta per sample, laid out as radii_) and centre_slopes_.
  double radius_slope_y(int j, int n) const;
  double radius_slope_theta(int j, int n) const;
  Vec2 centre_slope(int j) const;
  std::vector<std::array<double, 2>> slopes_;
  std::vector<Vec2> centre_slopes_;
  FormLandmarks landmarks_;
};

// Checks that the reference lines a skirt's pattern needs are really on the form (a form from a
// scan gets them from its girth profile, which any shape has): a waist that narrows (its girth
// at least 3 % below the hip's and not at the end of its search band), a hip at least 8 cm below
// it, side lines within 30 degrees of the sides. Returns "" or an error naming `name` and every
// line that cannot be found.
std::string check_reference_lines(const DressForm& form, const std::string& name);

}  // namespace drape::sim
