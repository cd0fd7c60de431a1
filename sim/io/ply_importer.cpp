// Stanford PLY read into an assimp scene (see ply_importer.hpp).
#include "sim/io/ply_importer.hpp"

#include <assimp/importerdesc.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <assimp/IOStream.hpp>
#include <assimp/IOSystem.hpp>
#include <bit>
#include <cctype>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "sim/io/importer_scene.hpp"

namespace drape::sim {

namespace {

const aiImporterDesc kDesc = {
    "drape PLY reader (vertex x y z [nx ny nz] [uv], face lists)",
    "",
    "",
    "",
    aiImporterFlags_SupportTextFlavour | aiImporterFlags_SupportBinaryFlavour,
    0,
    0,
    0,
    0,
    "ply"};

enum class Type : uint8_t { I8, U8, I16, U16, I32, U32, F32, F64 };
enum class Format : uint8_t { Ascii, Little, Big };

struct Property {
  std::string name;
  bool list = false;
  Type count_type = Type::U8;  // lists only
  Type type = Type::F32;       // the scalar's, or the list items'
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> props;
};

struct Header {
  Format format = Format::Ascii;
  std::vector<Element> elements;
  size_t body = 0;  // the offset of the first byte after "end_header\n"
};

// What the body's vertex and face elements hold.
struct PlyData {
  std::vector<std::array<float, 8>> vertices;  // x y z nx ny nz u v
  bool normals = false, uvs = false;
  std::vector<unsigned> corners;  // every kept face's vertex indices, face after face
  std::vector<unsigned> face_sizes;
};

[[noreturn]] void fail(const std::string& what) {
  throw std::runtime_error(what.c_str());
}

size_t type_size(Type t) {
  static constexpr size_t kSizes[] = {1, 1, 2, 2, 4, 4, 4, 8};
  return kSizes[static_cast<size_t>(t)];
}

// The type a PLY name stands for; false when it names none.
bool parse_type(std::string_view s, Type& t) {
  static constexpr std::pair<std::string_view, Type> kTypes[] = {
      {"char", Type::I8},   {"uchar", Type::U8},   {"short", Type::I16},   {"ushort", Type::U16},
      {"int", Type::I32},   {"uint", Type::U32},   {"float", Type::F32},   {"double", Type::F64},
      {"int8", Type::I8},   {"uint8", Type::U8},   {"int16", Type::I16},   {"uint16", Type::U16},
      {"int32", Type::I32}, {"uint32", Type::U32}, {"float32", Type::F32}, {"float64", Type::F64}};
  for (const auto& [name, type] : kTypes)
    if (s == name) {
      t = type;
      return true;
    }
  return false;
}

// A PLY name (element or property): one word that starts with a letter.
bool ply_word(std::string_view w) {
  return !w.empty() && std::isalpha(static_cast<unsigned char>(w[0])) &&
         std::all_of(w.begin(), w.end(), [](char ch) {
           return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_';
         });
}

std::vector<std::string_view> tokens(std::string_view l) {
  std::vector<std::string_view> t;
  for (size_t a = 0; a < l.size();) {
    while (a < l.size() && (l[a] == ' ' || l[a] == '\t')) ++a;
    size_t b = a;
    while (b < l.size() && l[b] != ' ' && l[b] != '\t') ++b;
    if (b > a) t.push_back(l.substr(a, b - a));
    a = b;
  }
  return t;
}

[[noreturn]] void header_fail(std::string_view line, const std::string& what) {
  fail("PLY header: \"" + std::string(line.substr(0, 40)) + "\" " + what);
}

void parse_format(const std::vector<std::string_view>& t, std::string_view l, Header& h,
                  bool& have_format) {
  if (have_format) header_fail(l, "is a second format line");
  const bool ok =
      t.size() == 3 && t[2] == "1.0" &&
      (t[1] == "ascii" || t[1] == "binary_little_endian" || t[1] == "binary_big_endian");
  if (!ok) header_fail(l, "is not \"format ascii|binary_* 1.0\"");
  h.format = t[1] == "ascii"                  ? Format::Ascii
             : t[1] == "binary_little_endian" ? Format::Little
                                              : Format::Big;
  have_format = true;
}

// "element NAME COUNT": a count above the file's size `n` is a lie (every entry takes a byte).
void parse_element(const std::vector<std::string_view>& t, std::string_view l, size_t n,
                   Header& h) {
  uint64_t c = 0;
  const std::string_view count = t.size() == 3 ? t[2] : std::string_view();
  const auto [end, ec] = std::from_chars(count.data(), count.data() + count.size(), c);
  if (t.size() != 3 || !ply_word(t[1]) || count.empty() || ec != std::errc() ||
      end != count.data() + count.size())
    header_fail(l, "is not \"element NAME COUNT\"");
  if (c > n)
    fail("PLY header: \"" + std::string(l) + "\" declares more entries than the file has bytes");
  for (const Element& e : h.elements)
    if (e.name == t[1]) header_fail(l, "declares a second element \"" + e.name + "\"");
  h.elements.push_back({std::string(t[1]), c, {}});
}

void parse_property(const std::vector<std::string_view>& t, std::string_view l, Header& h) {
  Property p;
  const bool scalar = t.size() == 3 && parse_type(t[1], p.type) && ply_word(t[2]);
  const bool list = t.size() == 5 && t[1] == "list" && parse_type(t[2], p.count_type) &&
                    parse_type(t[3], p.type) && ply_word(t[4]);
  if (!scalar && !list) header_fail(l, "is not \"property TYPE NAME\"");
  if (h.elements.empty()) header_fail(l, "comes before any element");
  p.list = list;
  p.name = std::string(t.back());
  for (const Property& q : h.elements.back().props)
    if (q.name == p.name) header_fail(l, "declares a second property \"" + p.name + "\"");
  h.elements.back().props.push_back(p);
}

// One header line after the magic, trailing spaces and '\r' removed.
void parse_header_line(std::string_view l, size_t n, Header& h, bool& have_format) {
  if (l.empty()) fail("PLY header: an empty line before end_header");
  const std::vector<std::string_view> t = tokens(l);
  if (t.empty()) header_fail(l, "is a line of blanks");
  if (t[0] == "comment" || t[0] == "obj_info") return;
  if (t[0] == "format") return parse_format(t, l, h, have_format);
  if (t[0] == "element") return parse_element(t, l, n, h);
  if (t[0] == "property") return parse_property(t, l, h);
  fail("PLY header: unknown line \"" + std::string(l.substr(0, 40)) + "\"");
}

Header parse_header(std::string_view f) {
  Header h;
  bool have_format = false;
  for (size_t line = 0, no = 0; line < f.size(); ++no) {
    const size_t end = f.find('\n', line);
    if (end == std::string_view::npos) break;
    std::string_view l = f.substr(line, end - line);
    while (!l.empty() && (l.back() == '\r' || l.back() == ' ')) l.remove_suffix(1);
    line = end + 1;
    if (no == 0) {
      if (l != "ply") fail("PLY header: the first line is not \"ply\"");
    } else if (l == "end_header") {
      if (!have_format) fail("PLY header: no format line before end_header");
      h.body = line;
      return h;
    } else {
      parse_header_line(l, f.size(), h, have_format);
    }
  }
  fail("PLY header has no end_header line");
}

// Reads the body's scalars in order, ASCII tokens or binary values, and names the element,
// entry and property it is at in every error.
class BodyReader {
 public:
  BodyReader(std::string_view f, const Header& h) : f_(f), pos_(h.body), format_(h.format) {}

  void at(const Element& e, uint64_t entry) {
    element_ = &e;
    entry_ = entry;
    prop_ = nullptr;
  }
  void at(const Property& p) { prop_ = &p; }
  size_t left() const { return f_.size() - pos_; }
  bool ascii() const { return format_ == Format::Ascii; }

  double scalar(Type t) { return ascii() ? ascii_scalar() : binary_scalar(t); }

  // A list's count, checked against the bytes left (an item takes its size, or in ASCII a
  // separator and a character) before anything is allocated from it.
  uint64_t list_count(const Property& p) {
    const double c = scalar(p.count_type);
    if (c < 0 || c != std::floor(c)) fail_here("list count " + number(c) + " is not a count");
    const uint64_t per = ascii() ? 2 : type_size(p.type);
    if (c > static_cast<double>(left() / per))
      fail_here("a list of " + number(c) + " items, more than the file's " +
                std::to_string(left()) + " bytes left hold");
    return static_cast<uint64_t>(c);
  }

  // Whether the element's declared count fits the bytes left at its smallest entry size.
  void check_count(const Element& e) {
    uint64_t per = 0;
    for (const Property& p : e.props)
      per += ascii() ? 1 : type_size(p.list ? p.count_type : p.type);
    if (per > 0 && e.count > left() / per)
      fail("PLY body: element \"" + e.name + "\" declares " + std::to_string(e.count) +
           " entries of at least " + std::to_string(per) + " bytes, more than the file's " +
           std::to_string(left()) + " bytes left");
  }

  // Nothing but (in ASCII) white space may follow the last element.
  void finish() {
    if (ascii())
      while (pos_ < f_.size() && std::isspace(static_cast<unsigned char>(f_[pos_]))) ++pos_;
    if (pos_ == f_.size()) return;
    if (!ascii())
      fail("PLY body: " + std::to_string(left()) + " bytes more than the header declares");
    size_t end = pos_;
    while (end < f_.size() && end - pos_ < 20 && !std::isspace(static_cast<unsigned char>(f_[end])))
      ++end;
    fail("PLY body: more data than the header declares (\"" +
         std::string(f_.substr(pos_, end - pos_)) + "\" and after)");
  }

  [[noreturn]] void fail_here(const std::string& what) const {
    std::string where = "PLY body: element \"" + element_->name + "\" entry " +
                        std::to_string(entry_) + " of " + std::to_string(element_->count);
    if (prop_) where += ", property \"" + prop_->name + "\"";
    fail(where + ": " + what);
  }

  static std::string number(double v) {
    if (v == std::floor(v) && std::fabs(v) < 1e18) return std::to_string(static_cast<int64_t>(v));
    char buf[32];
    const auto [end, ec] = std::to_chars(buf, buf + sizeof(buf), v);
    return std::string(buf, ec == std::errc() ? end : buf);
  }

 private:
  double ascii_scalar() {
    while (pos_ < f_.size() && std::isspace(static_cast<unsigned char>(f_[pos_]))) ++pos_;
    const size_t b = pos_;
    while (pos_ < f_.size() && !std::isspace(static_cast<unsigned char>(f_[pos_]))) ++pos_;
    if (pos_ == b) fail_here("the file ends here");
    std::string_view tok = f_.substr(b, pos_ - b);
    if (tok.size() > 1 && tok[0] == '+' && tok[1] != '-')
      tok.remove_prefix(1);  // from_chars takes no '+'
    double v = 0;
    const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (ec != std::errc() || end != tok.data() + tok.size() || !std::isfinite(v))
      fail_here("\"" + std::string(f_.substr(b, std::min<size_t>(20, pos_ - b))) +
                "\" is not a number");
    return v;
  }

  template <class T>
  T load() {
    std::array<unsigned char, sizeof(T)> b;
    std::memcpy(b.data(), f_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    if ((format_ == Format::Big) != (std::endian::native == std::endian::big))
      std::reverse(b.begin(), b.end());
    T v;
    std::memcpy(&v, b.data(), sizeof(T));
    return v;
  }

  double binary_scalar(Type t) {
    if (left() < type_size(t)) fail_here("the file ends inside it");
    switch (t) {
      case Type::I8:
        return load<int8_t>();
      case Type::U8:
        return load<uint8_t>();
      case Type::I16:
        return load<int16_t>();
      case Type::U16:
        return load<uint16_t>();
      case Type::I32:
        return load<int32_t>();
      case Type::U32:
        return load<uint32_t>();
      case Type::F32:
        return load<float>();
      case Type::F64:
        return load<double>();
    }
    return 0;
  }

  std::string_view f_;
  size_t pos_;
  Format format_;
  const Element* element_ = nullptr;
  uint64_t entry_ = 0;
  const Property* prop_ = nullptr;
};

// Where each vertex property goes: a slot of PlyData::vertices' arrays, or -1 (skipped).
std::vector<int> vertex_slots(const Element& e, PlyData& d) {
  static constexpr std::pair<std::string_view, int> kNames[] = {
      {"x", 0}, {"y", 1}, {"z", 2}, {"nx", 3}, {"ny", 4},        {"nz", 5},
      {"s", 6}, {"t", 7}, {"u", 6}, {"v", 7},  {"texture_u", 6}, {"texture_v", 7}};
  std::vector<int> slot(e.props.size(), -1);
  unsigned seen = 0;  // a bit per slot
  for (size_t i = 0; i < e.props.size(); ++i)
    for (const auto& [name, s] : kNames)
      if (e.props[i].name == name && !e.props[i].list && !(seen & (1u << s))) {
        slot[i] = s;
        seen |= 1u << s;
      }
  if ((seen & 7u) != 7u) fail("PLY header: element \"vertex\" lacks a scalar property x, y or z");
  d.normals = (seen & 0x38u) == 0x38u;
  d.uvs = (seen & 0xc0u) == 0xc0u;
  return slot;
}

// The face element's vertex index list: its property's position.
size_t face_list(const Element& e) {
  for (size_t i = 0; i < e.props.size(); ++i)
    if ((e.props[i].name == "vertex_indices" || e.props[i].name == "vertex_index") &&
        e.props[i].list)
      return i;
  fail("PLY header: element \"face\" has no list property vertex_indices or vertex_index");
}

// One property of an entry skipped: a scalar, or a list with its items.
void skip(BodyReader& r, const Property& p) {
  r.at(p);
  if (!p.list) {
    r.scalar(p.type);
    return;
  }
  const uint64_t n = r.list_count(p);
  for (uint64_t k = 0; k < n; ++k) r.scalar(p.type);
}

void read_vertices(BodyReader& r, const Element& e, PlyData& d) {
  const std::vector<int> slot = vertex_slots(e, d);
  d.vertices.resize(e.count, {0, 0, 0, 0, 0, 0, 0, 0});  // check_count bounded it
  for (uint64_t i = 0; i < e.count; ++i) {
    r.at(e, i);
    for (size_t k = 0; k < e.props.size(); ++k) {
      if (slot[k] < 0) {
        skip(r, e.props[k]);
        continue;
      }
      r.at(e.props[k]);
      d.vertices[i][static_cast<size_t>(slot[k])] = static_cast<float>(r.scalar(e.props[k].type));
    }
  }
}

// One face's vertex indices, each a whole number below `vertices` (the declared count).
void read_face(BodyReader& r, const Property& p, uint64_t vertices, PlyData& d) {
  r.at(p);
  const uint64_t n = r.list_count(p);
  if (n == 0) r.fail_here("a face of no corners");
  const size_t first = d.corners.size();
  for (uint64_t k = 0; k < n; ++k) {
    const double v = r.scalar(p.type);
    if (v < 0 || v != std::floor(v) || v >= static_cast<double>(vertices))
      r.fail_here("vertex index " + BodyReader::number(v) + " (item " + std::to_string(k) +
                  ") is not one of the " + std::to_string(vertices) + " vertices");
    d.corners.push_back(static_cast<unsigned>(v));
  }
  if (n < 3) {  // a point or a line: dropped by the loader anyway
    d.corners.resize(first);
    return;
  }
  d.face_sizes.push_back(static_cast<unsigned>(n));
}

void read_faces(BodyReader& r, const Element& e, uint64_t vertices, PlyData& d) {
  const size_t list = face_list(e);
  for (uint64_t i = 0; i < e.count; ++i) {
    r.at(e, i);
    for (size_t k = 0; k < e.props.size(); ++k) {
      if (k == list)
        read_face(r, e.props[k], vertices, d);
      else
        skip(r, e.props[k]);
    }
  }
}

PlyData parse(std::string_view f) {
  const Header h = parse_header(f);
  uint64_t vertices = 0;
  for (const Element& e : h.elements)
    if (e.name == "vertex") vertices = e.count;
  if (vertices >= UINT_MAX) fail("PLY header: too many vertices");
  BodyReader r(f, h);
  PlyData d;
  for (const Element& e : h.elements) {
    r.check_count(e);
    if (e.name == "vertex") {
      read_vertices(r, e, d);
    } else if (e.name == "face") {
      read_faces(r, e, vertices, d);
    } else if (!e.props.empty()) {  // an element of no properties holds no bytes to skip
      for (uint64_t i = 0; i < e.count; ++i) {
        r.at(e, i);
        for (const Property& p : e.props) skip(r, p);
      }
    }
  }
  r.finish();
  if (d.face_sizes.empty()) fail("PLY: no faces (of three or more corners)");
  return d;
}

aiMesh* make_mesh(const PlyData& d) {
  auto* mesh = new aiMesh();
  const auto n = static_cast<unsigned>(d.vertices.size());
  mesh->mNumVertices = n;
  mesh->mVertices = new aiVector3D[n];
  if (d.normals) mesh->mNormals = new aiVector3D[n];
  if (d.uvs) {
    mesh->mTextureCoords[0] = new aiVector3D[n];
    mesh->mNumUVComponents[0] = 2;
  }
  for (unsigned i = 0; i < n; ++i) {
    const std::array<float, 8>& v = d.vertices[i];
    mesh->mVertices[i] = aiVector3D(v[0], v[1], v[2]);
    if (d.normals) mesh->mNormals[i] = aiVector3D(v[3], v[4], v[5]);
    if (d.uvs) mesh->mTextureCoords[0][i] = aiVector3D(v[6], v[7], 0);
  }
  mesh->mNumFaces = static_cast<unsigned>(d.face_sizes.size());
  mesh->mFaces = new aiFace[mesh->mNumFaces];
  size_t next = 0;
  for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
    aiFace& face = mesh->mFaces[f];
    face.mNumIndices = d.face_sizes[f];
    face.mIndices = new unsigned[face.mNumIndices];
    std::copy_n(d.corners.begin() + static_cast<std::ptrdiff_t>(next), face.mNumIndices,
                face.mIndices);
    next += face.mNumIndices;
    mesh->mPrimitiveTypes |=
        face.mNumIndices == 3 ? aiPrimitiveType_TRIANGLE : aiPrimitiveType_POLYGON;
  }
  return mesh;
}

class PlyImporter : public Assimp::BaseImporter {
 public:
  // Data whose first word is "ply" in any case (after white space) is PLY's, as assimp's own
  // test has it; the header then holds it to the exact magic.
  bool CanRead(const std::string& file, Assimp::IOSystem* io, bool) const override {
    auto close = [io](Assimp::IOStream* s) { io->Close(s); };
    std::unique_ptr<Assimp::IOStream, decltype(close)> in(io->Open(file, "rb"), close);
    if (!in) return false;
    char head[64] = {};
    const size_t got = in->Read(head, 1, sizeof(head));
    size_t i = 0;
    while (i < got && std::isspace(static_cast<unsigned char>(head[i]))) ++i;
    if (got - i < 3) return false;
    return std::tolower(static_cast<unsigned char>(head[i])) == 'p' &&
           std::tolower(static_cast<unsigned char>(head[i + 1])) == 'l' &&
           std::tolower(static_cast<unsigned char>(head[i + 2])) == 'y';
  }
  const aiImporterDesc* GetInfo() const override { return &kDesc; }

 protected:
  void InternReadFile(const std::string& file, aiScene* scene, Assimp::IOSystem* io) override {
    const std::string bytes = io_detail::read_whole_file(io, file, "PLY");
    const PlyData d = parse(bytes);
    io_detail::set_one_mesh(scene, make_mesh(d), "ply");
  }
};

}  // namespace

std::unique_ptr<Assimp::BaseImporter> make_ply_importer() {
  return std::make_unique<PlyImporter>();
}

}  // namespace drape::sim
