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

namespace drape::sim {

namespace {

// The most corners a polygon of an imported mesh may have (postprocess).
constexpr unsigned kMaxCorners = 1024;

// Post-processing runs in two passes (see postprocess()): assimp 5.2's Triangulate step aborts
// the process (ai_assert) on a face with no indices, which a malformed PLY produces (found by
// fuzz_mesh), and in one ReadFile call the validation does not run before it.
constexpr unsigned kImportFlags =
    aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType;

// Whether `p` starts with "ply" in any case: assimp takes each letter in either case
// (fuzz_mesh_ply: a header starting "plYply" passed the checks below unchecked and hung assimp).
bool ply_magic(const char* p) {
  return std::tolower(static_cast<unsigned char>(p[0])) == 'p' &&
         std::tolower(static_cast<unsigned char>(p[1])) == 'l' &&
         std::tolower(static_cast<unsigned char>(p[2])) == 'y';
}

// A PLY name (element or property): one word that starts with a letter.
bool ply_word(std::string_view w) {
  return !w.empty() && std::isalpha(static_cast<unsigned char>(w[0])) &&
         std::all_of(w.begin(), w.end(), [](char ch) {
           return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_';
         });
}

bool ply_type(std::string_view t) {
  static constexpr std::string_view kTypes[] = {
      "char", "uchar", "short", "ushort", "int",   "uint",   "float",   "double",
      "int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"};
  return std::find(std::begin(kTypes), std::end(kTypes), t) != std::end(kTypes);
}

std::vector<std::string_view> ply_tokens(std::string_view l) {
  std::vector<std::string_view> t;
  for (size_t a = 0; a < l.size();) {
    const size_t b = std::min(l.find(' ', a), l.size());
    if (b > a) t.push_back(l.substr(a, b - a));
    a = b + 1;
  }
  return t;
}

// What is wrong with one header line after the magic ("" when nothing): assimp 5.2 hangs or
// allocates without bound on lines outside the format's grammar (fuzz_mesh, fuzz_mesh_ply: a
// mangled "property" line, a blank line, "element vertexascii 1.0", a name of digits read as an
// 11.4 GB count, an element count of 57 GB), so each line is held to it. `n` is the file's size.
std::string ply_header_line_error(std::string_view l, size_t n) {
  const std::string quoted = "\"" + std::string(l.substr(0, 40)) + "\"";
  if (l.empty()) return "PLY header: an empty line before end_header";
  const std::vector<std::string_view> t = ply_tokens(l);
  const std::string_view kw = t[0];
  if (kw == "comment" || kw == "obj_info") return "";
  if (kw == "format") {
    const bool ok =
        t.size() == 3 &&
        (t[1] == "ascii" || t[1] == "binary_little_endian" || t[1] == "binary_big_endian") &&
        t[2] == "1.0";
    return ok ? "" : "PLY header: " + quoted + " is not \"format ascii|binary_* 1.0\"";
  }
  if (kw == "property") {
    const bool scalar = t.size() == 3 && ply_type(t[1]) && ply_word(t[2]);
    const bool list =
        t.size() == 5 && t[1] == "list" && ply_type(t[2]) && ply_type(t[3]) && ply_word(t[4]);
    return scalar || list ? "" : "PLY header: " + quoted + " is not \"property TYPE NAME\"";
  }
  if (kw != "element") return "PLY header: unknown line " + quoted;
  char* end = nullptr;
  const std::string count = t.size() == 3 ? std::string(t[2]) : std::string();
  const unsigned long long c = std::strtoull(count.c_str(), &end, 10);
  if (!ply_word(t.size() == 3 ? t[1] : "") || count.empty() || *end != '\0' || count[0] == '-')
    return "PLY header: " + quoted + " is not \"element NAME COUNT\"";
  // Every entry takes at least one byte of the file: a count above its size is a lie.
  if (c > n)
    return "PLY header: \"" + std::string(l) + "\" declares more entries than the file has bytes";
  return "";
}

// Data that assimp would read as PLY (it starts with "ply") must close its header within the
// first MiB with an "end_header" line (assimp 5.2 loops forever without one) and keep every
// header line to the format's grammar (ply_header_line_error); false with `error` set.
bool ply_header_closed(const char* p, size_t n, std::string& error) {
  size_t i = 0;
  while (i < n && std::isspace(static_cast<unsigned char>(p[i]))) ++i;
  if (n - i < 3 || !ply_magic(p + i)) return true;
  const size_t limit = std::min(n, size_t{1} << 20);
  size_t line = i;
  for (size_t k = i; k < limit; ++k) {
    if (p[k] != '\n') continue;
    std::string_view l(p + line, k - line);
    while (!l.empty() && (l.back() == '\r' || l.back() == ' ')) l.remove_suffix(1);
    if (l == "end_header") return true;
    // The magic stands alone on its line (fuzz_mesh_ply: "ply\0format ascii 1.0" read by
    // assimp as two lines, by these checks as one, let an ASCII body past the body's check).
    if (line == i && l.size() != 3) error = "PLY header: the first line is not \"ply\"";
    if (line > i) error = ply_header_line_error(l, n);
    if (!error.empty()) return false;
    line = k + 1;
  }
  error = "PLY header has no end_header line";
  return false;
}

// An ASCII PLY body must hold exactly what its header declares: per element entry, one number
// per scalar property, and per list property a count (a whole number, at most kMaxCorners)
// followed by that many numbers. assimp 5.2 reads a body whose tokens do not line up with the
// header in ways that can allocate without bound (fuzz_mesh: an 1158-byte file whose vertex
// line carried one number too many made it request ~18 GB before failing; seed
// fuzz/corpus/mesh_ply/regress_ply_ascii_misaligned). Binary and non-PLY data pass unchecked here;
// false with `error` set.
bool ply_ascii_body_consistent(const char* p, size_t n, std::string& error) {
  size_t i = 0;
  while (i < n && std::isspace(static_cast<unsigned char>(p[i]))) ++i;
  if (n - i < 3 || !ply_magic(p + i)) return true;
  struct Element {
    std::string name;
    unsigned long long count = 0;
    std::vector<bool> is_list;
  };
  std::vector<Element> elements;
  bool ascii = false;
  size_t line = i, body = n;
  for (size_t k = i; k < n; ++k) {
    if (p[k] != '\n') continue;
    std::string_view l(p + line, k - line);
    while (!l.empty() && std::isspace(static_cast<unsigned char>(l.back()))) l.remove_suffix(1);
    line = k + 1;
    if (l == "end_header") {
      body = k + 1;
      break;
    }
    if (l.substr(0, 7) == "format ") ascii = l.substr(7, 5) == "ascii";
    if (l.substr(0, 8) == "element ") {
      Element e;
      const size_t sp = l.rfind(' ');
      e.name = std::string(l.substr(8, sp > 8 ? sp - 8 : 0));
      e.count = std::strtoull(std::string(l.substr(sp + 1)).c_str(), nullptr, 10);
      elements.push_back(e);
    } else if (l.substr(0, 9) == "property " && !elements.empty()) {
      elements.back().is_list.push_back(l.substr(9, 5) == "list ");
    }
  }
  if (!ascii || body >= n) return true;  // binary, or no body (the header check reports it)
  size_t k = body;
  auto next = [&](std::string_view& tok) {
    while (k < n && std::isspace(static_cast<unsigned char>(p[k]))) ++k;
    const size_t b = k;
    while (k < n && !std::isspace(static_cast<unsigned char>(p[k]))) ++k;
    tok = std::string_view(p + b, k - b);
    return !tok.empty();
  };
  auto number = [](std::string_view tok) {
    const std::string t(tok);
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    return end && *end == '\0' && std::isfinite(v);
  };
  for (const Element& e : elements)
    for (unsigned long long entry = 0; entry < e.count; ++entry)
      for (size_t q = 0; q < e.is_list.size(); ++q) {
        const std::string where = "PLY body: element \"" + e.name + "\" entry " +
                                  std::to_string(entry) + " of " + std::to_string(e.count);
        std::string_view tok;
        if (!next(tok)) {
          error = where + ": the file ends before it";
          return false;
        }
        if (!number(tok)) {
          error = where + ": \"" + std::string(tok.substr(0, 20)) + "\" is not a number";
          return false;
        }
        if (!e.is_list[q]) continue;
        const std::string t(tok);
        char* end = nullptr;
        const unsigned long c = std::strtoul(t.c_str(), &end, 10);
        if (!end || *end != '\0') {
          error = where + ": list count \"" + t.substr(0, 20) + "\" is not a whole number";
          return false;
        }
        if (c > kMaxCorners) {
          error =
              where + ": a list of " + t + " corners (at most " + std::to_string(kMaxCorners) + ")";
          return false;
        }
        for (unsigned long j = 0; j < c; ++j) {
          if (!next(tok) || !number(tok)) {
            error = where + ": its list of " + std::to_string(c) + " numbers is cut short";
            return false;
          }
        }
      }
  std::string_view extra;
  if (next(extra)) {
    error = "PLY body: more numbers than the header declares (\"" +
            std::string(extra.substr(0, 20)) + "\" and after)";
    return false;
  }
  return true;
}

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
    // assimp's OBJ importer gives way to the project's (obj_importer.hpp says why).
    if (d && d->mName && std::string_view(d->mName) == "Wavefront Object Importer") keep = false;
    if (!keep) drop.push_back(imp.GetImporter(i));
  }
  // UnregisterLoader gives the importer back without deleting it (assimp 5.2): it is ours now
  // (LeakSanitizer flagged 8 importers per Assimp::Importer before this delete).
  for (Assimp::BaseImporter* b : drop) {
    imp.UnregisterLoader(b);
    delete b;
  }
  imp.RegisterLoader(make_obj_importer().release());  // the importer owns it
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
    if (!ply_header_closed(head.data(), static_cast<size_t>(in.gcount()), error))
      return make_error(path, error);
    // (An ASCII PLY's body is checked whole: read the rest of the file.)
    if (size > head.size() && head.find("format ascii") != std::string::npos) {
      head.resize(static_cast<size_t>(size));
      in.read(head.data() + (1u << 20), static_cast<std::streamsize>(size - (1u << 20)));
    }
    if (!ply_ascii_body_consistent(head.data(), head.size(), error)) return make_error(path, error);
    if (!glb_lengths_fit(head.data(), head.size(), size, error)) return make_error(path, error);
  }
  return read_scene(path, [&](Assimp::Importer& imp) { return imp.ReadFile(path, 0); });
}

Result<TriMesh> load_mesh_from_memory(const void* data, size_t size, const char* hint,
                                      const std::string& name) {
  if (!data || size == 0) return make_error(name, "empty file");
  {
    std::string error;
    if (!ply_header_closed(static_cast<const char*>(data), size, error))
      return make_error(name, error);
    if (!ply_ascii_body_consistent(static_cast<const char*>(data), size, error))
      return make_error(name, error);
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
