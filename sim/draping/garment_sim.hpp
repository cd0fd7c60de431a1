// The sewn garment simulated with physics (docs/draping.md, "The garment simulated"): the
// mirrored, sewn pieces of the pattern pipeline as one cloth with the fabric's preset (the
// remeshed flat pieces are its material coordinates, so its triangles rest at their pattern
// shape), the side seams and dart legs as hard ties (xpbd_ties.hpp; the centre seams are
// already one vertex), draped on the dress form by the real-time solver (XPBD, Coulomb friction
// on the form's cover, as the app drapes) from the geometric placement (pushed the contact offset
// off the form), run until it rests. The bodice and the dresses come as such a Garment too
// (BodiceResult::garment, dress_garment in bodice.hpp).
// Then the fit: ease (distance of the cloth from the form) and strain (stretch of each triangle
// against its flat pattern), the seams' largest gap and the sewn girths.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "sim/core/cloth.hpp"
#include "sim/core/scene_objects.hpp"
#include "sim/draping/mapping.hpp"
#include "sim/draping/sew.hpp"
#include "sim/solvers/xpbd/xpbd_options.hpp"
#include "sim/solvers/xpbd/xpbd_ties.hpp"

namespace drape::sim {

class DressForm;

struct GarmentSimOptions {
  double dt = 1.0 / 90.0;  // frame (s): the app's sim rate
  // XPBD substeps per frame: twice the solver's default. At 10 the tight skirt on the form does
  // not hold its girth against the contacts and the hard ties (it slides 9 cm down the form,
  // triangles stretched by 48 % rms); at 20 its waist stays within 6 mm of the form's waist.
  int substeps = 20;
  int threads = 2;
  int max_frames = 1800;  // 20 s simulated at most
  int min_frames = 30;    // simulated before rest is tested
  // At rest: the fastest vertex slower than rest_speed (m/s) for rest_frames frames in a row.
  double rest_speed = 0.01;
  int rest_frames = 30;
  double friction = kFormFriction;  // the cloth on the form's cover (as the app)
  double contact_offset = 0.002;    // m the cloth is kept off the form (SceneObjects::offset)
  int tie_passes = 2;               // tie projections per substep
  double band = 0.006;              // m: half height of the waist and hip bands of the fit
  // The waist band a band's height above the simulated waist seam instead of below it: a
  // bodice has no cloth below its waist seam.
  bool waist_band_above = false;
};

// Ease and strain in one band of heights (the waist, the hip): over the cloth's vertices there.
struct FitBand {
  double y = 0;  // height of the line (m)
  double ease_max_mm = 0, ease_mean_mm = 0;
  double girth_mm = 0;            // tape girth of the cloth at y (garment_girth)
  double girth_geometric_mm = 0;  // the same of the geometrically relaxed garment
  // The geometric garment lies on the form's surface (with the design's ease), the simulated
  // cloth contact_offset off it: its girth is that of the geometric garment plus 2 pi offset.
  double girth_expected_mm = 0;
  double girth_error_pct = 0;  // girth_mm against girth_expected_mm
  int vertices = 0;  // 0: no cloth at y (a bodice at the hip, a skirt at the bust): no girths
};

struct GarmentSimResult {
  Cloth cloth;  // the garment at rest (its triangles those of the Garment)
  std::vector<xpbd::Tie> ties;
  int frames = 0;
  bool at_rest = false;
  double wall_ms = 0, ms_per_frame = 0;
  double max_speed_end = 0;                           // m/s, fastest vertex in the last frame
  double seam_gap_start_mm = 0, seam_gap_max_mm = 0;  // largest tie gap before and after
  // Deepest vertex inside the form's surface (mm; 0 when none is inside), over the vertices in
  // the form's height range.
  double penetration_max_mm = 0;
  std::vector<double> ease;    // per vertex: signed distance from the form (m; NaN outside it)
  std::vector<double> strain;  // per triangle: the principal stretch furthest from 1, minus 1
  double strain_max_pct = 0, strain_rms_pct = 0;  // |strain| over the triangles
  double strain_median_pct = 0, strain_p95_pct = 0;
  // How far the sewn waist seam (its mean height) came down from the geometric placement (mm).
  double waist_seam_drop_mm = 0;
  FitBand waist, hip;
  FitBand bust;  // at the form's bust line (a bodice, a dress)
  std::string to_json() const;
};

// Simulates the garment on the form until it rests (or max_frames). `surf` (the pipeline's
// mapping surface, its ease included) gives the girths' section centres.
Result<GarmentSimResult> simulate_garment(const Garment& garment,
                                          std::shared_ptr<const DressForm> form,
                                          const MappingSurface& surf, const FabricParams& fabric,
                                          const GarmentSimOptions& opt = {});

// The XPBD options a sewn garment drapes with (opt's substeps and threads; no coarse correction
// and no static finish, which know no ties; double-precision kernels). Sleep (freeze) stays off:
// simulate_garment steps to its own rest test; the live app turns it on.
XpbdOptions garment_xpbd_options(const GarmentSimOptions& opt);

// The principal stretch furthest from 1, minus 1, of triangle t of the cloth (flat pattern ->
// positions).
double triangle_strain(const Cloth& cloth, int t);

// The cloth of a sewn garment at its geometric placement: material coordinates, lumped masses.
Cloth garment_cloth(const Garment& g, const FabricParams& fabric);

}  // namespace drape::sim
