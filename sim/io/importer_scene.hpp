// What the project's assimp importers (obj_importer, ply_importer) share: the file read whole
// through assimp's IO system, and the one-mesh scene they hand back.
#pragma once

#include <assimp/material.h>
#include <assimp/scene.h>

#include <assimp/IOStream.hpp>
#include <assimp/IOSystem.hpp>
#include <memory>
#include <stdexcept>
#include <string>

namespace drape::sim::io_detail {

// The whole file; std::runtime_error "<format>: cannot ..." when it cannot be opened or read.
inline std::string read_whole_file(Assimp::IOSystem* io, const std::string& file,
                                   const std::string& format) {
  auto close = [io](Assimp::IOStream* s) { io->Close(s); };
  std::unique_ptr<Assimp::IOStream, decltype(close)> in(io->Open(file, "rb"), close);
  if (!in) throw std::runtime_error(format + ": cannot open the file");
  std::string bytes(in->FileSize(), '\0');
  if (in->Read(bytes.data(), 1, bytes.size()) != bytes.size())
    throw std::runtime_error(format + ": cannot read the whole file");
  return bytes;
}

// `scene` holds `mesh` (owned by the scene from here on) with one default material, under a
// root node named `root`.
inline void set_one_mesh(aiScene* scene, aiMesh* mesh, const char* root) {
  scene->mNumMeshes = 1;
  scene->mMeshes = new aiMesh* [1] { mesh };
  scene->mNumMaterials = 1;
  scene->mMaterials = new aiMaterial* [1] { new aiMaterial() };
  scene->mRootNode = new aiNode(root);
  scene->mRootNode->mNumMeshes = 1;
  scene->mRootNode->mMeshes = new unsigned[1]{0};
}

}  // namespace drape::sim::io_detail
