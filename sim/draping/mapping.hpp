// Geometric draping by mapping: flat cloth -> dress form along the grain.
// General mapping eqs. 2-1..2-9 on the section model, dart mapping eq. 2-10 zone by zone, the
// hip section's shape below the hip (tight skirt), ease as a radial offset of the surface.
#pragma once

#include <vector>

#include "sim/core/types.hpp"
#include "sim/draping/panel.hpp"

namespace drape::sim {

class DressForm;

// The surface the cloth is mapped onto: the form's section model, offset radially per section
// by the amount that makes that section's perimeter grow by exactly `ease`, and, when
// hip_shape_below_hip, the hip section's shape for every height below the hip (a tight skirt
// falls straight down from the hip), pushed out to the form's own section wherever the form is
// wider than that below the hip, so the skirt never cuts into the seat or thighs.
class MappingSurface {
 public:
  MappingSurface(const DressForm& form, double ease = 0.0, bool hip_shape_below_hip = true);
  const DressForm& form() const { return *form_; }
  double ease() const { return ease_; }
  double offset() const { return offset_; }  // nominal ease / 2pi (collision margin)
  // Height whose section shape is used at height y (the hip's below the hip).
  double shape_y(double y) const;
  double sample_radius(double y, int n) const;  // r of angle sample n (eq. 2-7), offset included
  Vec2 centre(double y) const;                  // (x, z) section centre
  double radius(double y, double theta) const;  // eq. 2-8
  Vec3 point(double y, double theta) const;     // eq. 2-9 in the stage frame
  double girth(double y) const;                 // perimeter of the 256-point section polygon

 private:
  const DressForm* form_;
  double ease_, offset_;
  bool hip_below_;
  std::vector<double> section_offset_;  // radial offset per form section
  // Below the hip: the hip section's shape pushed out wherever the form is wider (seat,
  // thighs), seen from the hip centre: env_[j * 256 + n] for sections j below the hip.
  std::vector<double> hip_r_, env_;
  double env_radius(int j, int n) const;
  void solve_offsets();  // per-section radial offsets for the ease
};

// Cumulative chord lengths around one section from angle sample n0 in direction dir
// (eqs. 2-3, 2-4): maps a weft distance to a centre angle (2-6) and back.
struct ArcTable {
  double theta0 = 0;
  int dir = 1;              // +1: theta increases (toward the form's left), -1: decreases
  std::vector<double> cum;  // 257 entries, cum[0] = 0
  static ArcTable build(const MappingSurface& s, double y, double theta0, int dir);
  double theta_at(double l) const;    // eq. 2-6 (extrapolates linearly past a full turn)
  double arc_at(double theta) const;  // inverse: arc from theta0 to theta in direction dir
};

// How one panel sits on the form: which centre line, which way round, where the top is, and
// the dart mapping constants of each slit (eq. 2-10).
struct PieceMapping {
  double theta_centre = 0;  // centre line angle (a sample: 0 front, pi back)
  int dir = -1;             // direction from the centre line toward the side line
  double theta_side = 0;    // side line angle
  double y_top = 0;         // height of the panel's top edge (eq. 2-1)
  double h_max = 0;         // panel height
  struct Dart {
    double l = 0;        // weft distance of the slit from the centre edge
    double y_tip = 0;    // height of the slit end on the form
    double theta_e = 0;  // centre angle of the slit end
    double a = 0;        // eq. 2-10 proportionality constant (rad / m), from the intake
    double intake = 0;   // wanted waist intake (m)
  };
  std::vector<Dart> darts;  // dart z separates zone z and z + 1

  double y_of_v(double v) const { return y_top - (h_max - v); }  // eq. 2-1
  double v_of_y(double y) const { return y - y_top + h_max; }
  // Start angle of zone z >= 1 at height y above its slit end (eq. 2-10).
  double zone_start_theta(int z, double y) const;
  // Arc shift c_z(y): a node of zone z at weft distance l maps to T.theta_at(l + c_z).
  double shift(int zone, double y, const ArcTable& T) const;
  // Angle of a node of zone `zone` at weft distance l, height y (eqs. 2-3..2-6, 2-10).
  double theta(int zone, double l, double y, const ArcTable& T) const;
  // Inverse of the mapping: the flat weft distance l of the point (y, theta) in zone `zone`.
  double l_at(int zone, double y, double theta, const ArcTable& T) const;
};

// Sets up the piece mapping for a panel: computes each dart's slit end angle and its constant a
// so that the intake at waist_y equals the slit's wanted intake.
PieceMapping make_piece_mapping(const Panel& panel, const MappingSurface& surf, double theta_centre,
                                int dir, double theta_side, double waist_y);

// Maps every node of the panel onto the surface (positions in panel.cloth.state.x).
void map_panel(Panel& panel, const MappingSurface& surf, const PieceMapping& pm);

// Grain deviation of the 3D cloth: angle (degrees) between each warp edge and the vertical
// meridian of the surface, and the kink between consecutive warp edges, near darts and overall.
struct GrainDeviation {
  std::vector<double> zone_mean_tilt_deg, zone_max_tilt_deg;
  double max_tilt_near_darts_deg = 0;  // warp edges within 3 columns of a slit, above its tip
  double max_kink_near_darts_deg = 0;  // change of the warp direction between consecutive edges
  double max_kink_deg = 0;             // same over the whole panel between hem and waist
};
GrainDeviation measure_grain(const Panel& panel, const MappingSurface& surf, double y_low,
                             double y_high);

}  // namespace drape::sim
