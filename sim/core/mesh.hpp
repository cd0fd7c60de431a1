// A plain triangle mesh: the exchange type between the cloth, the dress form, mesh files
// (sim/io) and the geometric draping.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "sim/core/types.hpp"

namespace drape::sim {

struct Cloth;

struct TriMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int32_t, 3>> triangles;
  std::vector<Vec2> uv;  // optional texture/material coordinates, one per vertex
  std::string name;
};

// The cloth's current shape as a mesh (uv = material coordinates).
TriMesh cloth_to_mesh(const Cloth& cloth, const std::string& name = "cloth");

}  // namespace drape::sim
