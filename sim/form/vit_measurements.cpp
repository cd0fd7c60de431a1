// Seamly2D / Valentina individual measurements (.vit) -> FormMeasurements. The XML is read with
// expat (line numbers for malformed files); the values are mapped onto the parametric form's
// fields and then go through the measurement JSON's own checks (parse_measurements), so a .vit
// form is held to the same ranges and height order as a measurement file.
#include "sim/form/vit_measurements.hpp"

#include <expat.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

namespace drape::sim {
namespace {

struct VitDoc {
  std::string source;
  std::vector<std::string> path;  // open elements
  std::string text;               // character data of the innermost element
  std::string root, unit, customer;
  int unit_line = 0;
  struct Value {
    std::string raw;
    int line = 0;
  };
  std::map<std::string, Value> m;
  std::string error;  // first semantic error (duplicate measurement, missing attribute)
  XML_Parser parser = nullptr;
};

int line_of(const VitDoc& d) {
  return static_cast<int>(XML_GetCurrentLineNumber(d.parser));
}

void on_start(void* ud, const XML_Char* name, const XML_Char** attrs) {
  auto& d = *static_cast<VitDoc*>(ud);
  d.text.clear();
  const std::string n = name;
  if (d.path.empty()) d.root = n;
  if (n == "m" && d.error.empty()) {
    std::string mname, value;
    bool has_name = false, has_value = false;
    for (int i = 0; attrs[i]; i += 2) {
      if (std::string(attrs[i]) == "name") mname = attrs[i + 1], has_name = true;
      if (std::string(attrs[i]) == "value") value = attrs[i + 1], has_value = true;
    }
    const std::string at = d.source + ":" + std::to_string(line_of(d)) + ": ";
    if (!has_name)
      d.error = at + "<m> without a name attribute";
    else if (!has_value)
      d.error = at + "measurement '" + mname + "' has no value attribute";
    else if (d.m.count(mname))
      d.error = at + "measurement '" + mname + "' given twice (first on line " +
                std::to_string(d.m[mname].line) + ")";
    else
      d.m[mname] = {value, line_of(d)};
  }
  d.path.push_back(n);
}

void on_end(void* ud, const XML_Char*) {
  auto& d = *static_cast<VitDoc*>(ud);
  if (d.path.size() == 2 && d.path.back() == "unit") {
    d.unit = d.text;
    d.unit_line = line_of(d);
  }
  if (d.path.size() == 3 && d.path.back() == "customer") d.customer = d.text;
  d.path.pop_back();
  d.text.clear();
}

void on_text(void* ud, const XML_Char* s, int len) {
  static_cast<VitDoc*>(ud)->text.append(s, static_cast<size_t>(len));
}

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r\n"), b = s.find_last_not_of(" \t\r\n");
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

}  // namespace

const std::vector<VitMapping>& vit_mappings() {
  static const std::vector<VitMapping> k{
      {"bust_girth", "bust girth", {"bust_circ", "bust_arc_f+bust_arc_b"}},
      {"waist_girth", "waist girth", {"waist_circ", "waist_arc_f+waist_arc_b"}},
      {"hip_girth", "hip girth", {"hip_circ", "hip_arc_f+hip_arc_b"}},
      {"height", "height", {"height"}},
      {"bust_height", "bust height", {"height_bust"}},
      {"waist_height", "waist height", {"height_waist_side", "height_waist_front"}},
      {"hip_height", "hip height", {"height_hip"}},
      {"neck_height", "neck height", {"height_neck_side", "height_neck_back", "height_neck_front"}},
  };
  return k;
}

Result<FormMeasurements> parse_vit(const std::string& xml, const std::string& source) {
  VitDoc d;
  d.source = source;
  XML_Parser p = XML_ParserCreate("UTF-8");
  if (!p) return Error{source + ": cannot create an XML parser"};
  d.parser = p;
  XML_SetUserData(p, &d);
  XML_SetElementHandler(p, on_start, on_end);
  XML_SetCharacterDataHandler(p, on_text);
  const bool ok = XML_Parse(p, xml.data(), static_cast<int>(xml.size()), 1) != XML_STATUS_ERROR;
  std::string xml_error;
  if (!ok)
    xml_error = source + ":" + std::to_string(XML_GetCurrentLineNumber(p)) +
                ": malformed XML: " + XML_ErrorString(XML_GetErrorCode(p));
  XML_ParserFree(p);
  if (!xml_error.empty()) return Error{xml_error};
  if (!d.error.empty()) return Error{d.error};
  if (d.root != "vit")
    return Error{source +
                 ": not a Valentina/Seamly2D individual measurements file (the root "
                 "element is <" +
                 d.root + ">, not <vit>)"};
  const std::string unit = trim(d.unit);
  double scale = 0;
  if (unit == "mm")
    scale = 0.001;
  else if (unit == "cm")
    scale = 0.01;
  else if (unit == "inch")
    scale = 0.0254;
  else if (unit.empty())
    return Error{source + ": <unit> missing (mm, cm or inch)"};
  else
    return Error{source + ":" + std::to_string(d.unit_line) + ": <unit> '" + unit +
                 "' unknown (mm, cm or inch)"};
  const auto value = [&](const std::string& name, double* out) -> std::string {
    const auto it = d.m.find(name);
    if (it == d.m.end()) return "absent";
    const std::string raw = trim(it->second.raw);
    char* end = nullptr;
    const double v = std::strtod(raw.c_str(), &end);
    if (raw.empty() || end != raw.c_str() + raw.size() || !std::isfinite(v))
      return source + ":" + std::to_string(it->second.line) + ": measurement '" + name +
             "': value '" + raw + "' is not a number (formulas are not supported)";
    *out = v * scale;
    return "";
  };
  nlohmann::json j;
  std::string missing;
  for (const VitMapping& mp : vit_mappings()) {
    bool found = false;
    for (const std::string& alt : mp.names) {
      const size_t plus = alt.find('+');
      double a = 0, b = 0;
      std::string ea = value(alt.substr(0, plus), &a), eb;
      if (plus != std::string::npos) eb = value(alt.substr(plus + 1), &b);
      if (ea != "absent" && !ea.empty()) return Error{ea};
      if (eb != "absent" && !eb.empty()) return Error{eb};
      if (ea.empty() && (plus == std::string::npos || eb.empty())) {
        j[mp.form_field] = a + b;
        found = true;
        break;
      }
    }
    if (!found) {
      std::string alts;
      for (const std::string& alt : mp.names) alts += (alts.empty() ? "" : " or ") + alt;
      missing += (missing.empty() ? "" : "; ") + std::string(mp.what) + " (" + alts + ")";
    }
  }
  if (!missing.empty())
    return Error{source + ": the form needs measurements the file lacks: " + missing};
  // The form's bottom (upper thigh): the gluteal fold's height when given, else 18 cm below the
  // hip (as on the standard forms: hip 0.78 m, bottom 0.60 m).
  double fold = 0;
  if (std::string e = value("height_gluteal_fold", &fold); e.empty())
    j["bottom_height"] = fold;
  else if (e != "absent")
    return Error{e};
  else
    j["bottom_height"] = j["hip_height"].get<double>() - 0.18;
  const std::string customer = trim(d.customer);
  j["size"] = customer.empty() ? std::filesystem::path(source).stem().string() : customer;
  auto m = parse_measurements(j.dump(), source + " (mapped from the .vit measurements)");
  if (!m) return Error{m.error()};
  return m;
}

Result<FormMeasurements> load_vit(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    return Error{path + ": not found or not a regular file"};
  std::ifstream f(path, std::ios::binary);
  if (!f) return Error{path + ": cannot open"};
  std::stringstream ss;
  ss << f.rdbuf();
  return parse_vit(ss.str(), path);
}

}  // namespace drape::sim
