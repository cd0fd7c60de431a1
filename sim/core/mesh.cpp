#include "sim/core/mesh.hpp"

#include "sim/core/cloth.hpp"

namespace drape::sim {

TriMesh cloth_to_mesh(const Cloth& cloth, const std::string& name) {
  TriMesh m;
  m.name = name;
  m.vertices = cloth.state.x;
  m.triangles = cloth.topo.triangles;
  if (cloth.topo.material.size() == m.vertices.size()) m.uv = cloth.topo.material;
  return m;
}

}  // namespace drape::sim
