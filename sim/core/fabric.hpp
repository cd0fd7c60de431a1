// Fabric parameters (SI) and their loading from JSON presets (assets/fabrics.json).
#pragma once

#include <map>
#include <string>

#include "sim/core/types.hpp"

namespace drape::sim {

// Membrane and bending properties of a woven fabric. Warp = grain = material v axis,
// weft = material u axis.
struct FabricParams {
  std::string name = "muslin";
  double areal_density = 0.13;  // kg/m^2
  double thickness = 0.0003;    // m
  double stretch_warp = 8000;   // N/m: force per unit width per unit strain along warp
  double stretch_weft = 5000;   // N/m
  double shear = 60;            // N/m per radian of shear angle
  double bending_warp =
      8.0e-6;  // N*m: moment per unit width per unit curvature (bending along warp)
  double bending_weft = 5.0e-6;  // N*m
  // Rayleigh factor (s), the preset's "damping": read and validated, kept in session logs; the
  // solvers take their damping from their own options (VbdOptions::rayleigh_damping, air drag).
  double rayleigh_damping = 0.0;
};

// The stiffnesses (stretch, shear, bending) of a and b are equal: what the energy is built from.
inline bool same_stiffness(const FabricParams& a, const FabricParams& b) {
  return a.stretch_warp == b.stretch_warp && a.stretch_weft == b.stretch_weft &&
         a.shear == b.shear && a.bending_warp == b.bending_warp && a.bending_weft == b.bending_weft;
}
// Every physical value of a and b is equal (the stiffnesses, density, thickness and damping; the
// name aside).
inline bool same_values(const FabricParams& a, const FabricParams& b) {
  return same_stiffness(a, b) && a.areal_density == b.areal_density && a.thickness == b.thickness &&
         a.rayleigh_damping == b.rayleigh_damping;
}

// Loads every preset of a fabrics JSON file. Each value is checked: present, finite, positive
// (damping may be 0). Errors name the file and the field, e.g. "fabrics.json: muslin.shear: ...".
Result<std::map<std::string, FabricParams>> load_fabric_presets(const std::string& path);
// Parses the same format from a string; `source` names it in errors.
Result<std::map<std::string, FabricParams>> parse_fabric_presets(const std::string& json_text,
                                                                 const std::string& source);
// One preset by name from assets/fabrics.json (or the given file).
Result<FabricParams> load_fabric(const std::string& path, const std::string& name);

// Writes a preset's physical values into the JSON object `j` under the keys the presets use
// (areal_density .. bending_weft, in that order); the caller adds its own (name, damping,
// description, source).
template <class Json>
void put_fabric_values(Json& j, const FabricParams& f) {
  j["areal_density"] = f.areal_density;
  j["thickness"] = f.thickness;
  j["stretch_warp"] = f.stretch_warp;
  j["stretch_weft"] = f.stretch_weft;
  j["shear"] = f.shear;
  j["bending_warp"] = f.bending_warp;
  j["bending_weft"] = f.bending_weft;
}

}  // namespace drape::sim
