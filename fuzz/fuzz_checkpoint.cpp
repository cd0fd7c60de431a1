// libFuzzer target for the checkpoint reader (sim/ops/checkpoint.cpp): any bytes → a checkpoint
// or an error, no crash; a checkpoint that decodes encodes to bytes that decode to the same
// encoding again.
#include <cstddef>
#include <cstdint>

#include "sim/ops/checkpoint.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  drape::sim::WorldCheckpoint c;
  if (!drape::sim::decode_checkpoint(data, size, "fuzz", c).empty()) return 0;
  const auto bytes = drape::sim::encode_checkpoint(c);
  drape::sim::WorldCheckpoint again;
  if (!drape::sim::decode_checkpoint(bytes.data(), bytes.size(), "fuzz2", again).empty())
    __builtin_trap();
  if (drape::sim::encode_checkpoint(again) != bytes) __builtin_trap();
  return 0;
}
