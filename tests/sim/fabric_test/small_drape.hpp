// Shared by the drape tester's tests: a coarse, short drape test (10 rings, 3 s, 10 finish
// cycles: seconds, not minutes) and a fabric of the given bending (N m), warp and weft alike.
#pragma once

#include "sim/fabric_test/drape_tester.hpp"

namespace drape::sim {

inline DrapeTestOptions small() {
  DrapeTestOptions o;
  o.resolution = 10;
  o.max_time = 3;
  o.finish_cycles = 10;
  return o;
}

inline FabricParams with_bending(double b) {
  FabricParams f;
  f.bending_warp = f.bending_weft = b;
  return f;
}

}  // namespace drape::sim
