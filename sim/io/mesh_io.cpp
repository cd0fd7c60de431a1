// Triangle meshes in and out through assimp.
#include "sim/io/mesh_io.hpp"

#include <assimp/BaseImporter.h>
#include <assimp/importerdesc.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string_view>
#include <vector>

#include "sim/io/obj_importer.hpp"
#include "sim/io/ply_importer.hpp"

namespace drape::sim {

namespace {

// The most corners a polygon of an imported mesh may have (postprocess).
constexpr unsigned kMaxCorners = 1024;

// Post-processing runs in two passes (see postprocess()): assimp 5.2's Triangulate step aborts
// the process (ai_assert) on a face with no indices, which a malformed PLY produces (found by
// fuzz_mesh), and in one ReadFile call the validation does not run before it.
constexpr unsigned kImportFlags =
    aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType;

// assimp 5.2's binary glTF readers allocate the length a chunk header claims before they
// compare it with the file (fuzz_mesh_glb: a 1688-byte GLB whose JSON chunk claimed 0xffff01e4
// bytes made it request 4 GB; seed fuzz/corpus/mesh_glb/regress_glb_huge_chunk). Data that
// starts with the magic "glTF" must declare a total length of 20 bytes or more within
// `file_size`, and every chunk header among the `n` bytes at hand a length within that total;
// false with `error` set.
bool glb_lengths_fit(const char* p, size_t n, uint64_t file_size, std::string& error) {
  if (n < 4 || std::string_view(p, 4) != "glTF") return true;
  auto u32 = [&](size_t at) {
    uint32_t v = 0;
    for (int b = 3; b >= 0; --b) v = (v << 8) | static_cast<unsigned char>(p[at + b]);
    return v;
  };
  if (n < 20) {
    error = "GLB: the file ends inside its header";
    return false;
  }
  // The total must hold the header and a chunk's (assimp subtracts the header from it
  // unchecked: fuzz_mesh_glb, a total of 0 made it request 2.6 GB; seed regress_glb_zero_length).
  const uint64_t total = u32(8);
  if (total < 20 || total > file_size) {
    error = "GLB header: a length of " + std::to_string(total) +
            " bytes (at least 20), the file has " + std::to_string(file_size);
    return false;
  }
  auto chunk_fits = [&](uint64_t at, uint64_t len, uint64_t head) {
    if (total >= at + head && len <= total - at - head) return true;
    error = "GLB: a chunk at byte " + std::to_string(at) + " claims " + std::to_string(len) +
            " bytes, past the length in the header (" + std::to_string(total) + ")";
    return false;
  };
  // glTF 1.0's binary header holds the JSON's length after the total (the JSON at byte 20);
  // 2.0's chunks follow the 12-byte header, each after its length and type.
  if (u32(4) == 1) return chunk_fits(12, u32(12), 8);
  for (uint64_t at = 12; at + 8 <= std::min<uint64_t>(n, total); at += 8 + u32(at))
    if (!chunk_fits(at, u32(at), 8)) return false;
  return true;
}

// Validates the raw scene (assimp's own checks, then face sizes and indices) before any step
// that assumes a valid scene; returns the post-processed scene or nullptr with `error` set.
const aiScene* postprocess(Assimp::Importer& imp, const aiScene* scene, std::string& error) {
  if (!scene) {
    error = imp.GetErrorString();
    return nullptr;
  }
  scene = imp.ApplyPostProcessing(aiProcess_ValidateDataStructure);
  if (!scene) {
    error = imp.GetErrorString();
    return nullptr;
  }
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    for (unsigned i = 0; i < mesh->mNumFaces; ++i) {
      const aiFace& face = mesh->mFaces[i];
      if (face.mNumIndices == 0 || !face.mIndices) {
        error = "mesh " + std::to_string(m) + " face " + std::to_string(i) + " has no vertices";
        return nullptr;
      }
      // assimp 5.2's Triangulate (ear clipping) ran for more than two minutes on 96 faces of
      // 31019 corners each, from a mangled PLY list count (fuzz_mesh timeout, seed
      // fuzz/corpus/mesh_ply/regress_ply_huge_face). A face cannot have more corners
      // than its mesh has vertices, and no form needs a polygon of more than kMaxCorners.
      if (face.mNumIndices > std::min(mesh->mNumVertices, kMaxCorners)) {
        error = "mesh " + std::to_string(m) + " face " + std::to_string(i) + " has " +
                std::to_string(face.mNumIndices) + " corners (at most " +
                std::to_string(kMaxCorners) + ", and not more than the mesh's " +
                std::to_string(mesh->mNumVertices) + " vertices)";
        return nullptr;
      }
      for (unsigned k = 0; k < face.mNumIndices; ++k)
        if (face.mIndices[k] >= mesh->mNumVertices) {
          error = "mesh " + std::to_string(m) + " face " + std::to_string(i) +
                  " refers to a vertex out of range";
          return nullptr;
        }
    }
  }
  scene = imp.ApplyPostProcessing(kImportFlags);
  if (!scene) error = imp.GetErrorString();
  return scene;
}

void configure(Assimp::Importer& imp) {
  // Drop point and line primitives (SortByPType): a form is made of faces.
  imp.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  // Only the formats the product reads (docs/dress-form.md): every other assimp 5.2 importer is
  // unregistered, so a stray file cannot reach their parsers (fuzz_mesh found a heap overflow
  // in one of them on an 18-byte input).
  static const char* const kKeep[] = {"obj", "ply", "stl", "gltf", "glb", "fbx", "dae"};
  std::vector<Assimp::BaseImporter*> drop;
  for (size_t i = 0; i < imp.GetImporterCount(); ++i) {
    const aiImporterDesc* d = imp.GetImporterInfo(i);
    bool keep = false;
    for (const char* ext : kKeep)
      if (d && d->mFileExtensions &&
          std::string_view(d->mFileExtensions).find(ext) != std::string_view::npos)
        keep = true;
    // assimp's OBJ and PLY importers give way to the project's (obj_importer.hpp and
    // ply_importer.hpp say why).
    if (d && d->mName && std::string_view(d->mName) == "Wavefront Object Importer") keep = false;
    if (d && d->mFileExtensions && std::string_view(d->mFileExtensions) == "ply") keep = false;
    if (!keep) drop.push_back(imp.GetImporter(i));
  }
  // UnregisterLoader gives the importer back without deleting it (assimp 5.2): it is ours now
  // (LeakSanitizer flagged 8 importers per Assimp::Importer before this delete).
  for (Assimp::BaseImporter* b : drop) {
    imp.UnregisterLoader(b);
    delete b;
  }
  imp.RegisterLoader(make_obj_importer().release());  // the importer owns them
  imp.RegisterLoader(make_ply_importer().release());
}

void collect(const aiScene* scene, const aiNode* node, const aiMatrix4x4& parent, TriMesh& out,
             bool& bad_index) {
  const aiMatrix4x4 m = parent * node->mTransformation;
  for (unsigned k = 0; k < node->mNumMeshes; ++k) {
    if (node->mMeshes[k] >= scene->mNumMeshes) {
      bad_index = true;
      continue;
    }
    const aiMesh* mesh = scene->mMeshes[node->mMeshes[k]];
    if (!mesh || !mesh->mVertices) continue;
    const int32_t base = static_cast<int32_t>(out.vertices.size());
    const bool has_uv = mesh->HasTextureCoords(0);
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D p = m * mesh->mVertices[v];
      out.vertices.emplace_back(p.x, p.y, p.z);
      if (has_uv)
        out.uv.emplace_back(mesh->mTextureCoords[0][v].x, mesh->mTextureCoords[0][v].y);
      else
        out.uv.emplace_back(0.0, 0.0);
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;
      std::array<int32_t, 3> t;
      for (int c = 0; c < 3; ++c) {
        if (face.mIndices[c] >= mesh->mNumVertices) {
          bad_index = true;
          t[c] = -1;
        } else {
          t[c] = base + static_cast<int32_t>(face.mIndices[c]);
        }
      }
      if (t[0] >= 0 && t[1] >= 0 && t[2] >= 0) out.triangles.push_back(t);
    }
  }
  for (unsigned c = 0; c < node->mNumChildren; ++c)
    if (node->mChildren[c]) collect(scene, node->mChildren[c], m, out, bad_index);
}

Result<TriMesh> convert(const aiScene* scene, const std::string& name,
                        const std::string& importer_error) {
  if (!scene) {
    std::string why = importer_error.empty() ? "unknown reason" : importer_error;
    return make_error(name,
                      "cannot be read as a mesh (truncated, corrupt or not a mesh "
                      "format assimp reads): " +
                          why);
  }
  if (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE)
    return make_error(name, "incomplete scene (no mesh data; not a mesh file?)");
  if (scene->mNumMeshes == 0 || !scene->mRootNode) return make_error(name, "contains no mesh");
  TriMesh out;
  out.name = std::filesystem::path(name).stem().string();
  bool bad_index = false;
  collect(scene, scene->mRootNode, aiMatrix4x4(), out, bad_index);
  if (bad_index) return make_error(name, "corrupt mesh: index out of range");
  if (out.triangles.empty()) return make_error(name, "contains no triangles");
  for (size_t i = 0; i < out.vertices.size(); ++i) {
    if (!out.vertices[i].allFinite()) {
      std::ostringstream os;
      os << "vertex " << i << " has a non-finite coordinate (NaN or inf)";
      return make_error(name, os.str());
    }
  }
  bool any_uv = false;
  for (const Vec2& t : out.uv) any_uv = any_uv || t != Vec2::Zero();
  if (!any_uv) out.uv.clear();
  return out;
}

// Reads with a new, configured importer (`read` calls ReadFile or ReadFileFromMemory on it),
// validates and post-processes, converts. The importer is not kept between files: assimp 5.2's
// importers keep state from one file to the next (fuzz_mesh_ply corrupted the heap within
// 10 000 executions when one importer read them all).
template <class Read>
Result<TriMesh> read_scene(const std::string& name, Read read) {
  Assimp::Importer imp;
  configure(imp);
  const aiScene* scene = nullptr;
  try {
    scene = read(imp);
  } catch (const std::exception& e) {  // assimp reports through the return value; be safe
    return make_error(name, std::string("cannot be read as a mesh: ") + e.what());
  }
  std::string error;
  scene = postprocess(imp, scene, error);
  return convert(scene, name, error);
}

}  // namespace

Result<TriMesh> load_mesh(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) return make_error(path, "file not found");
  if (!fs::is_regular_file(path, ec)) return make_error(path, "not a regular file");
  const auto size = fs::file_size(path, ec);
  if (ec) return make_error(path, "cannot read file size: " + ec.message());
  if (size == 0) return make_error(path, "empty file");
  {
    std::ifstream in(path, std::ios::binary);
    std::string head(static_cast<size_t>(std::min<std::uintmax_t>(size, 1u << 20)), '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    std::string error;
    if (!glb_lengths_fit(head.data(), static_cast<size_t>(in.gcount()), size, error))
      return make_error(path, error);
  }
  return read_scene(path, [&](Assimp::Importer& imp) { return imp.ReadFile(path, 0); });
}

Result<TriMesh> load_mesh_from_memory(const void* data, size_t size, const char* hint,
                                      const std::string& name) {
  if (!data || size == 0) return make_error(name, "empty file");
  {
    std::string error;
    if (!glb_lengths_fit(static_cast<const char*>(data), size, size, error))
      return make_error(name, error);
  }
  return read_scene(name, [&](Assimp::Importer& imp) {
    return imp.ReadFileFromMemory(data, size, 0, hint ? hint : "");
  });
}

std::string write_meshes(const std::string& path, const std::vector<TriMesh>& meshes) {
  namespace fs = std::filesystem;
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const char* format = ext == ".gltf"  ? "gltf2"
                       : ext == ".glb" ? "glb2"
                       : ext == ".obj" ? "obj"
                                       : nullptr;
  if (!format) return path + ": unsupported extension (use .gltf, .glb or .obj)";
  if (meshes.empty()) return path + ": nothing to write (no meshes)";
  for (const TriMesh& m : meshes) {
    const auto nv = static_cast<int64_t>(m.vertices.size());
    if (m.triangles.empty() || nv == 0) return path + ": mesh '" + m.name + "' is empty";
    for (const auto& t : m.triangles)
      for (int32_t i : t)
        if (i < 0 || i >= nv) return path + ": mesh '" + m.name + "' has an index out of range";
    for (const Vec3& v : m.vertices)
      if (!v.allFinite()) return path + ": mesh '" + m.name + "' has a non-finite vertex";
  }
  std::error_code ec;
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty()) fs::create_directories(parent, ec);

  auto scene = std::make_unique<aiScene>();
  scene->mNumMaterials = 1;
  scene->mMaterials = new aiMaterial*[1];
  scene->mMaterials[0] = new aiMaterial();
  aiString mat_name("default");
  scene->mMaterials[0]->AddProperty(&mat_name, AI_MATKEY_NAME);
  const unsigned n = static_cast<unsigned>(meshes.size());
  scene->mNumMeshes = n;
  scene->mMeshes = new aiMesh*[n];
  scene->mRootNode = new aiNode("root");
  scene->mRootNode->mNumChildren = n;
  scene->mRootNode->mChildren = new aiNode*[n];
  for (unsigned k = 0; k < n; ++k) {
    const TriMesh& src = meshes[k];
    const std::string nm = src.name.empty() ? "mesh" + std::to_string(k) : src.name;
    auto* mesh = new aiMesh();
    scene->mMeshes[k] = mesh;
    mesh->mName = aiString(nm);
    mesh->mMaterialIndex = 0;
    mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
    const unsigned nv = static_cast<unsigned>(src.vertices.size());
    mesh->mNumVertices = nv;
    mesh->mVertices = new aiVector3D[nv];
    mesh->mNormals = new aiVector3D[nv];
    std::vector<Vec3> normals(nv, Vec3::Zero());
    for (const auto& t : src.triangles) {
      const Vec3 a = src.vertices[t[0]], b = src.vertices[t[1]], c = src.vertices[t[2]];
      const Vec3 nrm = (b - a).cross(c - a);  // area weighted
      for (int32_t i : t) normals[i] += nrm;
    }
    for (unsigned v = 0; v < nv; ++v) {
      const Vec3& p = src.vertices[v];
      mesh->mVertices[v] = aiVector3D(static_cast<ai_real>(p.x()), static_cast<ai_real>(p.y()),
                                      static_cast<ai_real>(p.z()));
      const double len = normals[v].norm();
      const Vec3 nn = len > 0 ? Vec3(normals[v] / len) : Vec3(0, 1, 0);
      mesh->mNormals[v] = aiVector3D(static_cast<ai_real>(nn.x()), static_cast<ai_real>(nn.y()),
                                     static_cast<ai_real>(nn.z()));
    }
    if (src.uv.size() == nv) {
      mesh->mTextureCoords[0] = new aiVector3D[nv];
      mesh->mNumUVComponents[0] = 2;
      for (unsigned v = 0; v < nv; ++v)
        mesh->mTextureCoords[0][v] =
            aiVector3D(static_cast<ai_real>(src.uv[v].x()), static_cast<ai_real>(src.uv[v].y()), 0);
    }
    const unsigned nf = static_cast<unsigned>(src.triangles.size());
    mesh->mNumFaces = nf;
    mesh->mFaces = new aiFace[nf];
    for (unsigned f = 0; f < nf; ++f) {
      aiFace& face = mesh->mFaces[f];
      face.mNumIndices = 3;
      face.mIndices = new unsigned[3];
      for (int c = 0; c < 3; ++c) face.mIndices[c] = static_cast<unsigned>(src.triangles[f][c]);
    }
    auto* node = new aiNode(nm);
    node->mParent = scene->mRootNode;
    node->mNumMeshes = 1;
    node->mMeshes = new unsigned[1]{k};
    scene->mRootNode->mChildren[k] = node;
  }
  Assimp::Exporter exporter;
  aiReturn rc;
  try {
    rc = exporter.Export(scene.get(), format, path);
  } catch (const std::exception& e) {
    return path + ": export failed: " + e.what();
  }
  if (rc != aiReturn_SUCCESS) {
    const char* why = exporter.GetErrorString();
    return path + ": export failed: " + (why && *why ? why : "unknown error");
  }
  return {};
}

Result<DressForm> form_from_mesh_file(const std::string& path, const MeshImportOptions& opt) {
  auto mesh = load_mesh(path);
  if (!mesh) return Error{mesh.error()};
  return DressForm::from_triangles(*mesh, opt, path);
}

}  // namespace drape::sim
