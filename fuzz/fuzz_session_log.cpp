// libFuzzer target for the session file loader: any bytes → a session or an error, no crash.
#include <cstddef>
#include <cstdint>
#include <string>

#include "sim/ops/session_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto r = drape::sim::parse_session(text, "fuzz");
  if (r.ok()) {
    // A parsed session must serialise and parse back.
    auto again = drape::sim::parse_session(drape::sim::session_to_json(*r), "fuzz2");
    if (!again.ok()) __builtin_trap();
  }
  return 0;
}
