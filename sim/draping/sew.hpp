// Mirroring, sewing and relaxing the garment on the form: right pieces mirrored
// to the left, seams paired by label and joined (vertices identified where the seams are
// mirror images, stiff seam ties where the vertex counts differ), then a static relaxation.
#pragma once

#include <array>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "sim/draping/relax.hpp"
#include "sim/draping/remesh.hpp"
#include "sim/io/mesh_io.hpp"

namespace drape::sim {

// One right-half piece to sew: its pattern, its remeshed triangulation and the draped panel it
// came from (for the initial 3D placement of the remeshed vertices).
struct SewInput {
  const PatternPiece* piece = nullptr;
  const RemeshedPiece* mesh = nullptr;
  const Panel* panel = nullptr;
  // When set, the 3D start position of each remeshed vertex from its material point instead of
  // the panel (pieces changed flat after draping, such as a spread block: sim/draping/blocks.hpp).
  std::function<Vec3(const Vec2&)> place;
};

struct Garment {
  std::vector<Vec3> x;
  std::vector<Vec2> material;
  std::vector<std::array<int32_t, 3>> triangles;
  std::vector<int> vertex_piece;         // index into piece_names
  std::vector<std::string> piece_names;  // "Front (right)", "Front (left)", ...
  std::vector<SeamTie> ties;
  std::vector<int> waist_vertices;  // held at the waist height on the form while relaxing
  int merged_vertices = 0;          // vertices identified on mirrored centre seams
  std::vector<std::string> seams;   // human-readable list of the joins made
};

struct SewOptions {
  double mirror_x = 0.0;  // the mirror plane x = mirror_x (the form's centre plane)
  int relax_iterations = 200;
  double waist_y = std::numeric_limits<double>::quiet_NaN();  // waist height (NaN: start heights)
  // m per iteration toward the section centre: a tight skirt lies on the form (see sew.cpp); a
  // flared one stands away from it below the dart tips, where this would pull the flare in.
  double pressure_step = 1e-4;
};

Result<Garment> sew_garment(const std::vector<SewInput>& right, const MappingSurface& surf,
                            const SewOptions& opt, RelaxStats* stats = nullptr);

// Tape-measure girth of the garment at height y: the slice polygon ordered by angle.
double garment_girth(const Garment& g, const MappingSurface& surf, double y);

TriMesh garment_to_mesh(const Garment& g, const std::string& name = "garment");

}  // namespace drape::sim
