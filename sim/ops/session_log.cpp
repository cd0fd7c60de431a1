// Session files: JSON with base64 little-endian binary arrays (bit-exact doubles).
#include "sim/ops/session_log.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

namespace drape::sim {

static_assert(std::endian::native == std::endian::little,
              "session files store little-endian arrays; add byte swapping for this platform");

namespace {

using nlohmann::json;
constexpr const char* kFormat = "drape-session";
constexpr int kVersion = 1;
const char* kB64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

template <class T>
std::string enc(const std::vector<T>& v) {
  return base64_encode(v.data(), v.size() * sizeof(T));
}
std::string enc_vec3(const std::vector<Vec3>& v) {
  std::vector<double> d;
  d.reserve(v.size() * 3);
  for (const Vec3& p : v) d.insert(d.end(), {p.x(), p.y(), p.z()});
  return enc(d);
}
std::string enc_vec2(const std::vector<Vec2>& v) {
  std::vector<double> d;
  d.reserve(v.size() * 2);
  for (const Vec2& p : v) d.insert(d.end(), {p.x(), p.y()});
  return enc(d);
}
std::string hex64(uint64_t h) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}
std::vector<double> hand_doubles(const std::array<HandProxy, 2>& hands) {
  std::vector<double> d;
  for (const HandProxy& h : hands) {
    const auto& q = h.orientation.coeffs();  // x, y, z, w
    d.insert(d.end(), {h.position.x(), h.position.y(), h.position.z(), q[0], q[1], q[2], q[3],
                       h.tip.x(), h.tip.y(), h.tip.z(), h.radius});
  }
  return d;
}
const char* kind_name(SessionEvent::Kind k) {
  switch (k) {
    case SessionEvent::Kind::kHands:
      return "hands";
    case SessionEvent::Kind::kTrigger:
      return "trigger";
    case SessionEvent::Kind::kStroke:
      return "stroke";
    case SessionEvent::Kind::kSelect:
      return "select";
  }
  return "?";
}
const char* phase_name(TriggerPhase p) {
  return p == TriggerPhase::kBegin ? "begin" : p == TriggerPhase::kEnd ? "end" : "toggle";
}

// Reader with field paths in its errors.
struct Reader {
  std::string source;
  std::string err;
  bool fail(const std::string& field, const std::string& what) {
    if (err.empty()) err = source + ": " + field + ": " + what;
    return false;
  }
  const json* field(const json& obj, const std::string& path, const char* key) {
    if (!obj.is_object())
      return fail(path.empty() ? "top level" : path, "is not a JSON object"), nullptr;
    auto it = obj.find(key);
    if (it == obj.end()) return fail(path.empty() ? key : path + "." + key, "missing"), nullptr;
    return &*it;
  }
  bool number(const json& obj, const std::string& path, const char* key, double& out) {
    const json* f = field(obj, path, key);
    if (!f) return false;
    const std::string p = path.empty() ? key : path + "." + key;
    if (!f->is_number()) return fail(p, "must be a number");
    out = f->get<double>();
    if (!std::isfinite(out)) return fail(p, "must be finite");
    return true;
  }
  bool integer(const json& obj, const std::string& path, const char* key, int64_t lo, int64_t hi,
               int64_t& out) {
    const json* f = field(obj, path, key);
    if (!f) return false;
    const std::string p = path.empty() ? key : path + "." + key;
    if (!f->is_number_integer()) return fail(p, "must be an integer");
    if (f->is_number_unsigned() && f->get<uint64_t>() > static_cast<uint64_t>(INT64_MAX))
      return fail(p, "out of range");
    out = f->get<int64_t>();
    if (out < lo || out > hi)
      return fail(p, "out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return true;
  }
  bool boolean(const json& obj, const std::string& path, const char* key, bool& out) {
    const json* f = field(obj, path, key);
    if (!f) return false;
    if (!f->is_boolean()) return fail(path.empty() ? key : path + "." + key, "must be true/false");
    out = f->get<bool>();
    return true;
  }
  bool string(const json& obj, const std::string& path, const char* key, std::string& out) {
    const json* f = field(obj, path, key);
    if (!f) return false;
    if (!f->is_string()) return fail(path.empty() ? key : path + "." + key, "must be a string");
    out = f->get<std::string>();
    return true;
  }
  // A base64 array of `count` elements of T (count < 0: any multiple of sizeof(T)).
  template <class T>
  bool blob(const json& obj, const std::string& path, const char* key, int64_t count,
            std::vector<T>& out) {
    std::string s;
    if (!string(obj, path, key, s)) return false;
    const std::string p = path.empty() ? key : path + "." + key;
    std::vector<uint8_t> bytes;
    if (!base64_decode(s, bytes)) return fail(p, "is not valid base64");
    if (bytes.size() % sizeof(T) != 0)
      return fail(p, "has " + std::to_string(bytes.size()) + " bytes, not a multiple of " +
                         std::to_string(sizeof(T)));
    const size_t n = bytes.size() / sizeof(T);
    if (count >= 0 && n != static_cast<size_t>(count))
      return fail(p, "has " + std::to_string(n) + " values, expected " + std::to_string(count));
    out.resize(n);
    if (n) std::memcpy(out.data(), bytes.data(), bytes.size());
    if constexpr (std::is_floating_point_v<T>) {
      for (size_t i = 0; i < n; ++i)
        if (!std::isfinite(out[i])) return fail(p, "value " + std::to_string(i) + " is not finite");
    }
    return true;
  }
  bool vec3s(const json& obj, const std::string& path, const char* key, int64_t count,
             std::vector<Vec3>& out) {
    std::vector<double> d;
    if (!blob(obj, path, key, count < 0 ? -1 : 3 * count, d)) return false;
    if (d.size() % 3) return fail(path + "." + key, "length is not a multiple of 3");
    out.resize(d.size() / 3);
    for (size_t i = 0; i < out.size(); ++i) out[i] = Vec3(d[3 * i], d[3 * i + 1], d[3 * i + 2]);
    return true;
  }
};

bool read_hands(Reader& r, const json& e, const std::string& path, std::array<HandProxy, 2>& h) {
  std::vector<double> d;
  if (!r.blob(e, path, "pose", 22, d)) return false;
  const json* tr = r.field(e, path, "tracked");
  const json* co = r.field(e, path, "collides");
  if (!tr || !co) return false;
  if (!tr->is_array() || tr->size() != 2 || !(*tr)[0].is_boolean() || !(*tr)[1].is_boolean())
    return r.fail(path + ".tracked", "must be two booleans");
  if (!co->is_array() || co->size() != 2 || !(*co)[0].is_boolean() || !(*co)[1].is_boolean())
    return r.fail(path + ".collides", "must be two booleans");
  for (int k = 0; k < 2; ++k) {
    const double* p = d.data() + 11 * k;
    h[k].id = k;
    h[k].tracked = (*tr)[k].get<bool>();
    h[k].collides = (*co)[k].get<bool>();
    h[k].position = Vec3(p[0], p[1], p[2]);
    h[k].orientation = Eigen::Quaterniond(p[6], p[3], p[4], p[5]);  // w, x, y, z
    h[k].tip = Vec3(p[7], p[8], p[9]);
    h[k].radius = p[10];
    if (!(h[k].radius >= 0)) return r.fail(path + ".pose", "hand radius must be >= 0");
  }
  return true;
}

bool read_cloth(Reader& r, const json& c, Cloth& cloth) {
  const std::string P = "cloth";
  int64_t n = 0, nt = 0, nx = 0, ny = 0, version = 0;
  if (!r.integer(c, P, "vertices", 0, 50'000'000, n)) return false;
  if (!r.integer(c, P, "triangles_count", 0, 100'000'000, nt)) return false;
  if (!r.integer(c, P, "grid_nx", 0, 1'000'000, nx) ||
      !r.integer(c, P, "grid_ny", 0, 1'000'000, ny))
    return false;
  if (!r.integer(c, P, "topology_version", 0, INT64_MAX, version)) return false;
  std::vector<int32_t> tris;
  if (!r.blob(c, P, "triangles", 3 * nt, tris)) return false;
  cloth.topo.triangles.resize(nt);
  for (int64_t t = 0; t < nt; ++t) {
    for (int k = 0; k < 3; ++k) {
      const int32_t v = tris[3 * t + k];
      if (v < 0 || v >= n)
        return r.fail(P + ".triangles", "triangle " + std::to_string(t) + " has vertex index " +
                                            std::to_string(v) + " out of range");
      cloth.topo.triangles[t][k] = v;
    }
  }
  std::vector<double> mat;
  if (!r.blob(c, P, "material", 2 * n, mat)) return false;
  cloth.topo.material.resize(n);
  for (int64_t i = 0; i < n; ++i) cloth.topo.material[i] = Vec2(mat[2 * i], mat[2 * i + 1]);
  if (!r.blob(c, P, "vertex_zone", n, cloth.topo.vertex_zone)) return false;
  if (!r.blob(c, P, "triangle_zone", nt, cloth.topo.triangle_zone)) return false;
  if (!r.blob(c, P, "vertex_origin", n, cloth.topo.vertex_origin)) return false;
  for (int32_t o : cloth.topo.vertex_origin)
    if (o < 0 || o >= n) return r.fail(P + ".vertex_origin", "index out of range");
  if (!r.number(c, P, "spacing", cloth.topo.spacing)) return false;
  if (!(cloth.topo.spacing > 0)) return r.fail(P + ".spacing", "must be > 0");
  cloth.topo.grid_nx = static_cast<int>(nx);
  cloth.topo.grid_ny = static_cast<int>(ny);
  if (!r.vec3s(c, P, "x", n, cloth.state.x) || !r.vec3s(c, P, "x_prev", n, cloth.state.x_prev) ||
      !r.vec3s(c, P, "v", n, cloth.state.v))
    return false;
  if (!r.blob(c, P, "mass", n, cloth.state.mass) ||
      !r.blob(c, P, "inv_mass", n, cloth.state.inv_mass))
    return false;
  for (int64_t i = 0; i < n; ++i)
    if (cloth.state.mass[i] < 0 || cloth.state.inv_mass[i] < 0)
      return r.fail(P + ".mass", "vertex " + std::to_string(i) + " has a negative mass");
  if (!r.blob(c, P, "flags", n, cloth.state.flags)) return false;
  std::vector<double> time;
  if (!r.blob(c, P, "time", 1, time)) return false;
  cloth.state.time = time[0];
  cloth.topology_version = static_cast<uint64_t>(version);
  const json* f = r.field(c, P, "fabric");
  if (!f) return false;
  const std::string F = P + ".fabric";
  FabricParams& fp = cloth.fabric;
  if (!r.string(*f, F, "name", fp.name)) return false;
  struct {
    const char* key;
    double* v;
    bool may_be_zero;
  } nums[] = {{"areal_density", &fp.areal_density, false},
              {"thickness", &fp.thickness, false},
              {"stretch_warp", &fp.stretch_warp, false},
              {"stretch_weft", &fp.stretch_weft, false},
              {"shear", &fp.shear, false},
              {"bending_warp", &fp.bending_warp, false},
              {"bending_weft", &fp.bending_weft, false},
              {"damping", &fp.rayleigh_damping, true}};
  for (auto& e : nums) {
    if (!r.number(*f, F, e.key, *e.v)) return false;
    if (*e.v < 0 || (!e.may_be_zero && *e.v == 0)) return r.fail(F + "." + e.key, "must be > 0");
  }
  const std::string problem = cloth.validate();
  if (!problem.empty()) return r.fail(P, problem);
  return true;
}

}  // namespace

std::string base64_encode(const void* data, size_t n) {
  const auto* b = static_cast<const uint8_t*>(data);
  std::string out;
  out.reserve((n + 2) / 3 * 4);
  for (size_t i = 0; i < n; i += 3) {
    const uint32_t v = (uint32_t(b[i]) << 16) | (i + 1 < n ? uint32_t(b[i + 1]) << 8 : 0) |
                       (i + 2 < n ? uint32_t(b[i + 2]) : 0);
    out += kB64[(v >> 18) & 63];
    out += kB64[(v >> 12) & 63];
    out += i + 1 < n ? kB64[(v >> 6) & 63] : '=';
    out += i + 2 < n ? kB64[v & 63] : '=';
  }
  return out;
}

bool base64_decode(const std::string& s, std::vector<uint8_t>& out) {
  out.clear();
  if (s.size() % 4 != 0) return false;
  auto val = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  out.reserve(s.size() / 4 * 3);
  for (size_t i = 0; i < s.size(); i += 4) {
    int v[4];
    int pad = 0;
    for (int k = 0; k < 4; ++k) {
      const char c = s[i + k];
      if (c == '=') {
        if (i + 4 != s.size() || k < 2) return false;
        v[k] = 0;
        ++pad;
      } else {
        if (pad) return false;  // data after padding
        v[k] = val(c);
        if (v[k] < 0) return false;
      }
    }
    const uint32_t w =
        (uint32_t(v[0]) << 18) | (uint32_t(v[1]) << 12) | (uint32_t(v[2]) << 6) | uint32_t(v[3]);
    out.push_back(static_cast<uint8_t>(w >> 16));
    if (pad < 2) out.push_back(static_cast<uint8_t>(w >> 8));
    if (pad < 1) out.push_back(static_cast<uint8_t>(w));
  }
  return true;
}

std::string session_to_json(const SessionLog& log) {
  json j;
  j["format"] = kFormat;
  j["version"] = kVersion;
  j["step_dt"] = base64_encode(&log.step_dt, sizeof(double));
  const Cloth& c = log.initial;
  json jc;
  jc["vertices"] = c.num_vertices();
  jc["triangles_count"] = c.topo.num_triangles();
  std::vector<int32_t> tris;
  tris.reserve(c.topo.triangles.size() * 3);
  for (const auto& t : c.topo.triangles) tris.insert(tris.end(), t.begin(), t.end());
  jc["triangles"] = enc(tris);
  jc["material"] = enc_vec2(c.topo.material);
  jc["vertex_zone"] = enc(c.topo.vertex_zone);
  jc["triangle_zone"] = enc(c.topo.triangle_zone);
  jc["vertex_origin"] = enc(c.topo.vertex_origin);
  jc["spacing"] = c.topo.spacing;
  jc["grid_nx"] = c.topo.grid_nx;
  jc["grid_ny"] = c.topo.grid_ny;
  jc["topology_version"] = c.topology_version;
  jc["x"] = enc_vec3(c.state.x);
  jc["x_prev"] = enc_vec3(c.state.x_prev);
  jc["v"] = enc_vec3(c.state.v);
  jc["mass"] = enc(c.state.mass);
  jc["inv_mass"] = enc(c.state.inv_mass);
  jc["flags"] = enc(c.state.flags);
  jc["time"] = base64_encode(&c.state.time, sizeof(double));
  const FabricParams& f = c.fabric;
  jc["fabric"] = {{"name", f.name}, {"damping", f.rayleigh_damping}};
  put_fabric_values(jc["fabric"], f);
  j["cloth"] = std::move(jc);
  std::vector<double> plates, boxes, spheres;
  for (const Plate& p : log.plates)
    plates.insert(plates.end(),
                  {p.centre.x(), p.centre.y(), p.centre.z(), p.half_x, p.half_z, p.thickness});
  for (const Box& b : log.boxes)
    boxes.insert(boxes.end(),
                 {b.centre.x(), b.centre.y(), b.centre.z(), b.half.x(), b.half.y(), b.half.z()});
  for (const Sphere& s : log.spheres)
    spheres.insert(spheres.end(), {s.centre.x(), s.centre.y(), s.centre.z(), s.radius});
  j["scene"] = {{"floor", log.floor},
                {"offset", base64_encode(&log.offset, sizeof(double))},
                {"plates", enc(plates)},
                {"boxes", enc(boxes)},
                {"spheres", enc(spheres)}};
  json ev = json::array();
  for (const SessionEvent& e : log.events) {
    json je;
    je["step"] = e.step;
    je["type"] = kind_name(e.kind);
    switch (e.kind) {
      case SessionEvent::Kind::kHands:
        je["pose"] = enc(hand_doubles(e.hands));
        je["tracked"] = {e.hands[0].tracked, e.hands[1].tracked};
        je["collides"] = {e.hands[0].collides, e.hands[1].collides};
        break;
      case SessionEvent::Kind::kTrigger:
        je["name"] = e.name;
        je["phase"] = phase_name(e.phase);
        je["hand"] = e.hand;
        break;
      case SessionEvent::Kind::kStroke:
        je["hand"] = e.hand;
        je["points"] = enc_vec3(e.points);
        break;
      case SessionEvent::Kind::kSelect:
        je["hand"] = e.hand;
        je["index"] = e.index;
        break;
    }
    ev.push_back(std::move(je));
  }
  j["events"] = std::move(ev);
  j["final_step"] = log.final_step;
  j["final_hash"] = hex64(log.final_hash);
  return j.dump(1);
}

Result<SessionLog> parse_session(const std::string& text, const std::string& source) {
  try {
    json j = json::parse(text, nullptr, false);
    if (j.is_discarded()) return make_error(source, "not valid JSON");
    Reader r{source, {}};
    SessionLog log;
    std::string format;
    int64_t version = 0;
    if (!r.string(j, "", "format", format)) return Error{r.err};
    if (format != kFormat) return make_error(source, "format: expected \"drape-session\"");
    if (!r.integer(j, "", "version", 0, 1000, version)) return Error{r.err};
    if (version != kVersion)
      return make_error(source, "version: " + std::to_string(version) + " is not supported (1)");
    std::vector<double> dt;
    if (!r.blob(j, "", "step_dt", 1, dt)) return Error{r.err};
    if (!(dt[0] > 0 && dt[0] < 10)) return make_error(source, "step_dt: must be in (0, 10) s");
    log.step_dt = dt[0];
    const json* c = r.field(j, "", "cloth");
    if (!c || !read_cloth(r, *c, log.initial)) return Error{r.err};
    const json* sc = r.field(j, "", "scene");
    if (!sc) return Error{r.err};
    std::vector<double> off, plates, boxes, spheres;
    if (!r.boolean(*sc, "scene", "floor", log.floor) || !r.blob(*sc, "scene", "offset", 1, off) ||
        !r.blob(*sc, "scene", "plates", -1, plates) || !r.blob(*sc, "scene", "boxes", -1, boxes) ||
        !r.blob(*sc, "scene", "spheres", -1, spheres))
      return Error{r.err};
    if (!(off[0] >= 0 && off[0] < 1))
      return make_error(source, "scene.offset: must be in [0, 1) m");
    log.offset = off[0];
    if (plates.size() % 6 || boxes.size() % 6 || spheres.size() % 4)
      return make_error(source, "scene: plates/boxes need 6 values each, spheres 4");
    for (size_t i = 0; i < plates.size(); i += 6)
      log.plates.push_back({Vec3(plates[i], plates[i + 1], plates[i + 2]), plates[i + 3],
                            plates[i + 4], plates[i + 5]});
    for (size_t i = 0; i < boxes.size(); i += 6)
      log.boxes.push_back({Vec3(boxes[i], boxes[i + 1], boxes[i + 2]),
                           Vec3(boxes[i + 3], boxes[i + 4], boxes[i + 5])});
    for (size_t i = 0; i < spheres.size(); i += 4)
      log.spheres.push_back({Vec3(spheres[i], spheres[i + 1], spheres[i + 2]), spheres[i + 3]});
    const json* ev = r.field(j, "", "events");
    if (!ev) return Error{r.err};
    if (!ev->is_array()) return make_error(source, "events: must be an array");
    uint64_t last_step = 0;
    for (size_t i = 0; i < ev->size(); ++i) {
      const json& e = (*ev)[i];
      const std::string P = "events[" + std::to_string(i) + "]";
      SessionEvent out;
      int64_t step = 0;
      std::string type;
      if (!r.integer(e, P, "step", 0, INT64_MAX, step) || !r.string(e, P, "type", type))
        return Error{r.err};
      out.step = static_cast<uint64_t>(step);
      if (out.step < last_step) return make_error(source, P + ".step: steps must not decrease");
      last_step = out.step;
      int64_t hand = 1, index = 0;
      if (type == "hands") {
        out.kind = SessionEvent::Kind::kHands;
        if (!read_hands(r, e, P, out.hands)) return Error{r.err};
      } else if (type == "trigger") {
        out.kind = SessionEvent::Kind::kTrigger;
        std::string phase;
        if (!r.string(e, P, "name", out.name) || !r.string(e, P, "phase", phase) ||
            !r.integer(e, P, "hand", 0, 1, hand))
          return Error{r.err};
        if (out.name.empty() || out.name.size() > 32)
          return make_error(source, P + ".name: must be 1..32 characters");
        if (phase == "begin")
          out.phase = TriggerPhase::kBegin;
        else if (phase == "end")
          out.phase = TriggerPhase::kEnd;
        else if (phase == "toggle")
          out.phase = TriggerPhase::kToggle;
        else
          return make_error(source, P + ".phase: must be begin, end or toggle");
      } else if (type == "stroke") {
        out.kind = SessionEvent::Kind::kStroke;
        if (!r.integer(e, P, "hand", 0, 1, hand) || !r.vec3s(e, P, "points", -1, out.points))
          return Error{r.err};
      } else if (type == "select") {
        out.kind = SessionEvent::Kind::kSelect;
        if (!r.integer(e, P, "hand", 0, 1, hand) || !r.integer(e, P, "index", 0, 1000, index))
          return Error{r.err};
      } else {
        return make_error(source, P + ".type: unknown event type \"" + type + "\"");
      }
      out.hand = static_cast<int>(hand);
      out.index = static_cast<int>(index);
      log.events.push_back(std::move(out));
    }
    int64_t final_step = 0;
    std::string hash;
    if (!r.integer(j, "", "final_step", 0, INT64_MAX, final_step) ||
        !r.string(j, "", "final_hash", hash))
      return Error{r.err};
    if (static_cast<uint64_t>(final_step) < last_step)
      return make_error(source, "final_step: before the last event");
    log.final_step = static_cast<uint64_t>(final_step);
    if (hash.size() != 16 || hash.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos)
      return make_error(source, "final_hash: must be 16 hex digits");
    log.final_hash = std::stoull(hash, nullptr, 16);
    return log;
  } catch (const std::exception& e) {
    return make_error(source, std::string("malformed session: ") + e.what());
  }
}

Result<SessionLog> load_session(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return make_error(path, "cannot open");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_session(ss.str(), path);
}

std::string save_session(const std::string& path, const SessionLog& log) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return path + ": cannot open for writing";
  out << session_to_json(log) << '\n';
  out.close();
  if (!out) return path + ": write failed";
  return {};
}

}  // namespace drape::sim
