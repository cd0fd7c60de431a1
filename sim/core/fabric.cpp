// Fabric presets from JSON: every field checked (present, a number, finite, > 0; damping >= 0),
// errors naming the file and the field.
#include "sim/core/fabric.hpp"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

namespace drape::sim {
namespace {

std::string fmt_number(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

// Reads one numeric field; returns an error message or empty.
std::string read_field(const nlohmann::json& obj, const std::string& preset, const char* key,
                       bool required, bool allow_zero, double& out) {
  const std::string where = preset + "." + key;
  auto it = obj.find(key);
  if (it == obj.end()) return required ? where + ": missing" : std::string();
  if (!it->is_number()) return where + ": must be a number, got " + it->dump();
  const double x = it->get<double>();
  if (!std::isfinite(x)) return where + ": must be finite, got " + fmt_number(x);
  if (allow_zero ? x < 0 : x <= 0) {
    return where + (allow_zero ? ": must be >= 0, got " : ": must be > 0, got ") + fmt_number(x);
  }
  out = x;
  return {};
}

}  // namespace

Result<std::map<std::string, FabricParams>> parse_fabric_presets(const std::string& json_text,
                                                                 const std::string& source) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(json_text);
  } catch (const nlohmann::json::exception& e) {
    return make_error(source, std::string("invalid JSON: ") + e.what());
  }
  if (!doc.is_object()) return make_error(source, "top level must be an object of presets");
  std::map<std::string, FabricParams> out;
  for (auto it = doc.begin(); it != doc.end(); ++it) {
    const std::string& name = it.key();
    if (!name.empty() && name[0] == '_') continue;  // notes: "_units", "_source", ...
    if (!it->is_object()) return make_error(source, name + ": must be an object of parameters");
    FabricParams p;
    p.name = name;
    struct Field {
      const char* key;
      double* dst;
      bool required, allow_zero;
    };
    const Field fields[] = {
        {"areal_density", &p.areal_density, true, false},
        {"thickness", &p.thickness, true, false},
        {"stretch_warp", &p.stretch_warp, true, false},
        {"stretch_weft", &p.stretch_weft, true, false},
        {"shear", &p.shear, true, false},
        {"bending_warp", &p.bending_warp, true, false},
        {"bending_weft", &p.bending_weft, true, false},
        {"damping", &p.rayleigh_damping, false, true},
    };
    for (const Field& f : fields) {
      std::string e = read_field(*it, name, f.key, f.required, f.allow_zero, *f.dst);
      if (!e.empty()) return make_error(source, e);
    }
    out.emplace(name, p);
  }
  if (out.empty()) return make_error(source, "no fabric presets (only notes or empty)");
  return out;
}

Result<std::map<std::string, FabricParams>> load_fabric_presets(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return make_error(path, "cannot open file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_fabric_presets(ss.str(), path);
}

Result<FabricParams> load_fabric(const std::string& path, const std::string& name) {
  auto all = load_fabric_presets(path);
  if (!all) return Error{all.error()};
  auto it = all->find(name);
  if (it == all->end()) {
    std::string have;
    for (const auto& [k, v] : *all) have += (have.empty() ? "" : ", ") + k;
    return make_error(path, "no preset '" + name + "' (have: " + have + ")");
  }
  return it->second;
}

}  // namespace drape::sim
