// The flat muslin panel of geometric draping: a criss-cross grid with dart
// slits cut along element edges by node duplication, and zones from the slit extensions.
#pragma once

#include <string>
#include <vector>

#include "sim/core/cloth.hpp"
#include "sim/core/types.hpp"

namespace drape::sim {

class DressForm;

// A dart slit cut into the panel from its top edge before mapping.
struct DartSlit {
  double position = 0.1;  // m: weft distance of the slit from the centre-line edge
  double depth = 0.12;    // m: from the top edge down to the slit end (the dart tip)
  double intake = 0.015;  // m: dart intake wanted at the waist (sets eq. 2-10's constant a)
};

// Size and placement of one rectangular panel.
struct PanelDesign {
  double width = 0.28;            // m, along the weft (u)
  double height = 0.62;           // m, along the warp (v, grain)
  double spacing = 0.01;          // m, grid spacing (snapped so the width/height divide evenly)
  bool centre_edge_left = true;   // the u = 0 edge lies on the centre line (else u = width)
  double top_above_waist = 0.03;  // m: top edge this far above the waist line (eq. 2-1)
  std::vector<DartSlit> slits;
};

// One slit after cutting: grid column, rows, and the node pairs on both of its sides.
struct PanelSlit {
  int column = 0;     // grid column i of the slit
  int tip_row = 0;    // grid row of the slit end (not duplicated)
  double l = 0;       // weft distance from the centre edge (snapped)
  double v_tip = 0;   // material v of the slit end
  double intake = 0;  // wanted waist intake (m)
  int tip_node = -1;
  std::vector<int> near_nodes;  // nodes on the centre side (rows tip_row+1 .. top), zone k
  std::vector<int> far_nodes;   // their duplicates on the far side, zone k + 1
};

// The slit panel: the cloth plus what mapping and extraction need to know about it.
struct Panel {
  PanelDesign design;
  Cloth cloth;
  int nx = 0, ny = 0;            // grid vertices along u and v (before duplication)
  double dx = 0, dy = 0;         // actual grid spacing
  std::vector<PanelSlit> slits;  // ordered by distance from the centre edge
  int num_zones() const { return static_cast<int>(slits.size()) + 1; }
  // Weft distance from the centre-line edge of a material point (l of eq. 2-3).
  double centre_distance(double u) const { return design.centre_edge_left ? u : design.width - u; }
  double u_of_distance(double l) const { return design.centre_edge_left ? l : design.width - l; }
  // The (up to) two triangles of grid cell (i, j): index 2 * (j * (nx - 1) + i) + k.
  int cell_triangle(int i, int j, int k) const { return 2 * (j * (nx - 1) + i) + k; }
  // Barycentric coordinates of material point m in triangle tri (negative outside).
  Vec3 barycentric(int tri, const Vec2& m) const;
  // Triangle of the flat panel containing material point m (or -1), with barycentrics.
  int locate(const Vec2& m, Vec3* bary) const;
  // Same, among the triangles of one zone only (a point on a slit lies on both of its sides;
  // the zone says which layer). Falls back to locate() when no triangle of that zone is near.
  int locate_in_zone(const Vec2& m, int zone, Vec3* bary) const;
};

// Checks a panel description; `where` prefixes field names in errors ("pieces[0].panel").
// With a form, also rejects a panel larger than the form (wider than half the girth at the
// hip plus `ease`, or reaching below the floor from `top_y`). Returns "" when valid.
std::string validate_panel(const PanelDesign& d, const std::string& where,
                           const DressForm* form = nullptr, double ease = 0.0, double top_y = 0.0);

// Builds the flat panel: grid, slits by node duplication, zones per vertex and triangle.
Result<Panel> build_panel(const PanelDesign& d, const FabricParams& fabric,
                          const std::string& where = "panel");

}  // namespace drape::sim
