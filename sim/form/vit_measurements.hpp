// Forms from what pattern makers keep: a Seamly2D / Valentina individual measurements file
// (.vit, XML) mapped onto the parametric form's measurements (docs/dress-form.md).
#pragma once

#include <string>
#include <vector>

#include "sim/form/dress_form.hpp"

namespace drape::sim {

// One measurement the parametric form needs and the .vit names that can give it: the first
// name present is used; a pair "a+b" means the sum of two arcs (front + back).
struct VitMapping {
  const char* form_field;  // FormMeasurements field (as in the measurement JSON)
  const char* what;        // in words, for errors
  std::vector<std::string> names;
};
const std::vector<VitMapping>& vit_mappings();

// Parses a .vit document. Errors name the source and, for malformed XML, the line; a value
// that is not a plain number (a formula) names its measurement and line; every measurement
// the form needs and the file lacks is named in one error. `size` defaults to the customer's
// name, else the file name.
Result<FormMeasurements> parse_vit(const std::string& xml, const std::string& source);
Result<FormMeasurements> load_vit(const std::string& path);

}  // namespace drape::sim
