// Wavefront OBJ read into an assimp scene (see obj_importer.hpp).
#include "sim/io/obj_importer.hpp"

#include <assimp/importerdesc.h>
#include <assimp/scene.h>

#include <charconv>
#include <climits>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "sim/io/importer_scene.hpp"

namespace drape::sim {

namespace {

const aiImporterDesc kDesc = {"drape OBJ reader (geometry: v, vt, vn, f)",
                              "",
                              "",
                              "",
                              aiImporterFlags_SupportTextFlavour,
                              0,
                              0,
                              0,
                              0,
                              "obj"};

// One face corner: indices into the position, texture and normal lists (-1: none).
struct Corner {
  int64_t v = -1, t = -1, n = -1;
};

struct ObjData {
  std::vector<aiVector3D> v, vt, vn;
  std::vector<Corner> corners;  // every kept face's corners, face after face
  std::vector<unsigned> face_sizes;
};

[[noreturn]] void fail(size_t line, const std::string& what) {
  throw std::runtime_error(("OBJ line " + std::to_string(line) + ": " + what).c_str());
}

std::vector<std::string_view> split(std::string_view l) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < l.size()) {
    while (i < l.size() && (l[i] == ' ' || l[i] == '\t' || l[i] == '\r')) ++i;
    const size_t b = i;
    while (i < l.size() && l[i] != ' ' && l[i] != '\t' && l[i] != '\r') ++i;
    if (i > b) out.push_back(l.substr(b, i - b));
  }
  return out;
}

float number(std::string_view tok, size_t line) {
  std::string_view t = tok;
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);  // from_chars takes no '+'
  float x = 0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), x);
  if (t.empty() || ec != std::errc() || end != t.data() + t.size())
    fail(line, "\"" + std::string(tok.substr(0, 20)) + "\" is not a number (or out of range)");
  return x;
}

// "v", "vt", "vn": `min`..`max` numbers after the keyword; the first three (missing ones 0).
aiVector3D vector(const std::vector<std::string_view>& tok, size_t min, size_t max, size_t line) {
  if (tok.size() - 1 < min || tok.size() - 1 > max)
    fail(line, "\"" + std::string(tok[0]) + "\" takes " + std::to_string(min) + " to " +
                   std::to_string(max) + " numbers, not " + std::to_string(tok.size() - 1));
  float c[3] = {0, 0, 0};
  for (size_t i = 1; i < tok.size(); ++i) {
    const float x = number(tok[i], line);
    if (i <= 3) c[i - 1] = x;
  }
  return {c[0], c[1], c[2]};
}

// One index of a corner: 1-based, or negative counting back from the last of `count` so far;
// an empty one is "none" (-1). Positive indices are checked against the final counts later.
int64_t index(std::string_view s, size_t count, size_t line) {
  if (s.empty()) return -1;
  int64_t i = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), i);
  if (ec != std::errc() || end != s.data() + s.size() || i == 0)
    fail(line, "\"" + std::string(s.substr(0, 20)) + "\" is not an index (1-based or negative)");
  if (i > 0) return i - 1;
  if (static_cast<uint64_t>(-(i + 1)) >= count)
    fail(line, "a negative index reaches before the first");
  return static_cast<int64_t>(count) + i;
}

Corner corner(std::string_view tok, const ObjData& d, size_t line) {
  std::string_view part[3];
  size_t k = 0;
  for (size_t b = 0;; ++k) {
    if (k == 3) fail(line, "corner \"" + std::string(tok.substr(0, 20)) + "\" has over 3 parts");
    const size_t e = tok.find('/', b);
    part[k] = tok.substr(b, e == std::string_view::npos ? std::string_view::npos : e - b);
    if (e == std::string_view::npos) break;
    b = e + 1;
  }
  if (part[0].empty())
    fail(line, "corner \"" + std::string(tok.substr(0, 20)) + "\" has no vertex");
  return {index(part[0], d.v.size(), line), index(part[1], d.vt.size(), line),
          index(part[2], d.vn.size(), line)};
}

void parse_line(std::string_view l, size_t line, ObjData& d) {
  const std::vector<std::string_view> tok = split(l);
  if (tok.empty() || tok[0][0] == '#') return;
  if (tok[0] == "v") {
    d.v.push_back(vector(tok, 3, 7, line));  // x y z [w] or x y z r g b
  } else if (tok[0] == "vt") {
    d.vt.push_back(vector(tok, 1, 3, line));
  } else if (tok[0] == "vn") {
    d.vn.push_back(vector(tok, 3, 3, line));
  } else if (tok[0] == "f") {
    std::vector<Corner> face;
    for (size_t i = 1; i < tok.size(); ++i) face.push_back(corner(tok[i], d, line));
    if (face.size() < 3) return;  // a point or a line: dropped by the loader anyway
    if (d.corners.size() + face.size() >= UINT_MAX) fail(line, "too many face corners");
    d.corners.insert(d.corners.end(), face.begin(), face.end());
    d.face_sizes.push_back(static_cast<unsigned>(face.size()));
  }
}

ObjData parse(std::string_view text) {
  ObjData d;
  size_t line = 1;
  for (size_t b = 0; b < text.size(); ++line) {
    size_t e = text.find('\n', b);
    if (e == std::string_view::npos) e = text.size();
    parse_line(text.substr(b, e - b), line, d);
    b = e + 1;
  }
  if (d.face_sizes.empty()) throw std::runtime_error("OBJ: no faces (of three or more corners)");
  for (size_t c = 0; c < d.corners.size(); ++c) {
    const Corner& k = d.corners[c];
    if (k.v >= static_cast<int64_t>(d.v.size()) || k.t >= static_cast<int64_t>(d.vt.size()) ||
        k.n >= static_cast<int64_t>(d.vn.size()))
      throw std::runtime_error(("OBJ: face corner " + std::to_string(c) +
                                " refers to a vertex, texture coordinate or normal out of range")
                                   .c_str());
  }
  return d;
}

// One mesh of polygons with a vertex per face corner (UVs and normals where any corner has one).
aiMesh* make_mesh(const ObjData& d) {
  auto* mesh = new aiMesh();
  const auto n = static_cast<unsigned>(d.corners.size());
  bool any_t = false, any_n = false;
  for (const Corner& k : d.corners) {
    any_t = any_t || k.t >= 0;
    any_n = any_n || k.n >= 0;
  }
  mesh->mNumVertices = n;
  mesh->mVertices = new aiVector3D[n];
  if (any_t) {
    mesh->mTextureCoords[0] = new aiVector3D[n];
    mesh->mNumUVComponents[0] = 2;
  }
  if (any_n) mesh->mNormals = new aiVector3D[n];
  for (unsigned i = 0; i < n; ++i) {
    const Corner& k = d.corners[i];
    mesh->mVertices[i] = d.v[static_cast<size_t>(k.v)];
    if (any_t)
      mesh->mTextureCoords[0][i] = k.t >= 0 ? d.vt[static_cast<size_t>(k.t)] : aiVector3D();
    if (any_n) mesh->mNormals[i] = k.n >= 0 ? d.vn[static_cast<size_t>(k.n)] : aiVector3D(0, 1, 0);
  }
  mesh->mNumFaces = static_cast<unsigned>(d.face_sizes.size());
  mesh->mFaces = new aiFace[mesh->mNumFaces];
  unsigned next = 0;
  for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
    aiFace& face = mesh->mFaces[f];
    face.mNumIndices = d.face_sizes[f];
    face.mIndices = new unsigned[face.mNumIndices];
    for (unsigned c = 0; c < face.mNumIndices; ++c) face.mIndices[c] = next++;
    mesh->mPrimitiveTypes |=
        face.mNumIndices == 3 ? aiPrimitiveType_TRIANGLE : aiPrimitiveType_POLYGON;
  }
  return mesh;
}

class ObjImporter : public Assimp::BaseImporter {
 public:
  // The same test as assimp's OBJ importer, for files whose extension names no importer.
  bool CanRead(const std::string& file, Assimp::IOSystem* io, bool) const override {
    static const char* tokens[] = {"mtllib", "usemtl", "v ", "vt ", "vn ", "o ", "g ", "s ", "f "};
    return SearchFileHeaderForToken(io, file, tokens, std::size(tokens), 200, false, true);
  }
  const aiImporterDesc* GetInfo() const override { return &kDesc; }

 protected:
  void InternReadFile(const std::string& file, aiScene* scene, Assimp::IOSystem* io) override {
    const std::string text = io_detail::read_whole_file(io, file, "OBJ");
    const ObjData d = parse(text);
    io_detail::set_one_mesh(scene, make_mesh(d), "obj");
  }
};

}  // namespace

std::unique_ptr<Assimp::BaseImporter> make_obj_importer() {
  return std::make_unique<ObjImporter>();
}

}  // namespace drape::sim
