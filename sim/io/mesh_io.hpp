// Triangle meshes in and out through assimp (OBJ, PLY, STL, glTF/GLB read; glTF/OBJ written),
// and dress forms read from mesh files. The only unit of the simulation core that links assimp.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "sim/core/mesh.hpp"
#include "sim/form/dress_form.hpp"

namespace drape::sim {

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
// A dress form from a scanned or modelled mesh file (OBJ, PLY, STL, glTF): read with
// load_mesh, then resampled by DressForm::from_triangles. Errors name the file.
Result<DressForm> form_from_mesh_file(const std::string& path, const MeshImportOptions& opt = {});

}  // namespace drape::sim
