// libFuzzer target for the checkpoint reader (sim/ops/checkpoint.cpp): any bytes → a checkpoint
// or an error, no crash; a checkpoint that decodes encodes to bytes that decode to the same
// encoding again. Half the inputs get their records' CRCs made right first (the first byte's
// low bit chooses), so mutations of the payloads reach the record decoders instead of stopping
// at the CRC check. The solver's state of a checkpoint that decodes goes into the session's
// solver (XPBD cooking cuts ahead) with the checkpoint's cloth, when the cloth is small
// (restoring cooks it): its readers (sim/solvers/cook_ahead.cpp, sim/solvers/xpbd/xpbd_state.cpp)
// must reject what does not fit with an error, and the solver must then step (without the
// scene's objects but with self-collision, whose pairs the state carries: the solver's state is
// what is fuzzed).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "sim/ops/checkpoint.hpp"
#include "sim/runtime/journal.hpp"
#include "sim/solvers/cook_ahead.hpp"

namespace {

uint32_t get_u32(const unsigned char* p) {
  return p[0] | (p[1] << 8) | (p[2] << 16) | (static_cast<uint32_t>(p[3]) << 24);
}

void fix_crcs(std::vector<unsigned char>& d) {
  size_t pos = 12;
  while (pos + 8 <= d.size()) {
    const uint32_t len = get_u32(d.data() + pos);
    if (len > d.size() - pos - 8) return;
    const uint32_t crc = drape::sim::crc32(d.data() + pos + 8, len);
    for (int i = 0; i < 4; ++i) d[pos + 4 + i] = static_cast<unsigned char>(crc >> (8 * i));
    pos += 8 + len;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  std::vector<unsigned char> d(data + 1, data + size);
  if (data[0] & 1) fix_crcs(d);
  drape::sim::WorldCheckpoint c;
  if (!drape::sim::decode_checkpoint(d.data(), d.size(), "fuzz", c).empty()) return 0;
  const auto bytes = drape::sim::encode_checkpoint(c);
  drape::sim::WorldCheckpoint again;
  if (!drape::sim::decode_checkpoint(bytes.data(), bytes.size(), "fuzz2", again).empty())
    __builtin_trap();
  if (drape::sim::encode_checkpoint(again) != bytes) __builtin_trap();
  constexpr int kMaxVertices = 64;  // a cook per input: kept small
  if (!c.solver_state.empty() && c.cloth.num_vertices() <= kMaxVertices) {
    drape::sim::XpbdOptions o;
    o.threads = 1;
    o.freeze = true;
    o.finish_thread = false;
    drape::sim::CookAheadSolver solver(
        o, drape::sim::CookAheadOptions{
               .ticks = 8, .idle_priority = false, .worker_threads = 1, .spare_energy = false});
    (void)solver.restore_state(c.solver_state, c.cloth);
    drape::sim::SceneObjects scene;
    scene.self_collision = true;
    solver.step(c.cloth, scene, 1.0 / 90);
  }
  return 0;
}
