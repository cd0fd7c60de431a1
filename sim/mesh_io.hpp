// Triangle meshes in and out through assimp (OBJ, PLY, STL, glTF/GLB read; glTF/OBJ written).
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "sim/types.hpp"

namespace drape::sim {

struct Cloth;

struct TriMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int32_t, 3>> triangles;
  std::vector<Vec2> uv;  // optional texture/material coordinates, one per vertex
  std::string name;
};

// Reads every mesh of the file into one TriMesh (node transforms applied). Errors name the
// file: missing, empty, truncated, not a mesh, no triangles, non-finite coordinates.
Result<TriMesh> load_mesh(const std::string& path);
// The same from bytes in memory; `hint` is the format's file extension ("obj", "ply", "stl",
// "glb"; glTF with external buffers cannot be read from memory), `name` is used in errors.
Result<TriMesh> load_mesh_from_memory(const void* data, size_t size, const char* hint,
                                      const std::string& name);
// Writes one or more named meshes into a glTF 2.0 (.gltf + .bin, or .glb) or OBJ file,
// chosen by the extension. Returns an empty string or an error message.
std::string write_meshes(const std::string& path, const std::vector<TriMesh>& meshes);
// The cloth's current shape as a mesh (uv = material coordinates).
TriMesh cloth_to_mesh(const Cloth& cloth, const std::string& name = "cloth");

}  // namespace drape::sim
