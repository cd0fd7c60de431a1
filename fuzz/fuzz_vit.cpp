// Fuzz: Seamly2D / Valentina individual measurements (.vit XML) -> FormMeasurements ->
// parametric form (never crashes; errors only).
#include <cstddef>
#include <cstdint>
#include <string>

#include "sim/form/vit_measurements.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto m = drape::sim::parse_vit(text, "fuzz.vit");
  if (m.ok()) {
    // Measurements that pass the checks must give a form (coarse spacing keeps the fuzzer fast).
    auto f = drape::sim::DressForm::from_measurements(*m, 0.05);
    if (!f.ok()) __builtin_trap();
    (void)f->girth_at(m->waist_height);
  }
  return 0;
}
