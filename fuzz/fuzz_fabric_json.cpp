// Fuzz: fabric presets JSON (sim::parse_fabric_presets): errors only, never a crash.
#include <cstddef>
#include <cstdint>
#include <string>

#include "sim/core/fabric.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto presets = drape::sim::parse_fabric_presets(text, "fuzz.json");
  (void)presets.ok();
  return 0;
}
