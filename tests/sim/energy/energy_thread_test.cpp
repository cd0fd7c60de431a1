// ClothEnergy::build on a thread pool: the tensor bending's rows and vertex matrix are made in
// parts of rows, one per thread (sparse products, the per-triangle local estimators); the result
// must be the serial build's, bit for bit. (In the TSan build: "thread" in the name.)
#include <gtest/gtest.h>

#include <cstdio>

#include "sim/core/thread_pool.hpp"
#include "sim/energy/energy.hpp"
#include "sim/testbeds/testbed.hpp"

using namespace drape::sim;

namespace {

// A 56 x 56 panel (6 050 triangles: more than the 4 096 below which the build stays on one
// thread) with its first two rows pinned (rigid triangles, clamped hinges).
Cloth pinned_panel() {
  PanelSpec p;
  p.width = p.height = 0.5;
  p.nx = p.ny = 56;
  Cloth c = make_panel(p, FabricParams{});
  for (int i = 0; i < 2 * 56; ++i) c.state.flags[i] |= kFlagPinned;
  return c;
}

}  // namespace

TEST(EnergyThreads, TensorBendingBuiltOnAPoolIsTheSerialBuildBitForBit) {
  Cloth c = pinned_panel();
  ThreadPool pool(2);
  for (int smoothing : {1, 2})
    for (bool matrix : {false, true}) {
      EnergyOptions o;
      o.curvature_smoothing = smoothing;
      o.bending_matrix = matrix;
      ClothEnergy serial, parallel;
      serial.build(c, o);
      parallel.build(c, o, &pool);
      ASSERT_TRUE(serial.tensor_bending());
      ASSERT_GT(serial.num_bending_rows(), 4096);
      std::printf("smoothing %d, matrix %d: %d rows, %zu entries, P %zu entries\n", smoothing,
                  matrix, serial.num_bending_rows(), serial.bending_row_values().size(),
                  serial.bending_values().size());
      EXPECT_EQ(serial.bending_row_offsets(), parallel.bending_row_offsets());
      EXPECT_EQ(serial.bending_row_columns(), parallel.bending_row_columns());
      EXPECT_EQ(serial.bending_row_values(), parallel.bending_row_values());
      EXPECT_EQ(serial.has_bending_matrix(), matrix);
      EXPECT_EQ(serial.bending_offsets(), parallel.bending_offsets());
      EXPECT_EQ(serial.bending_columns(), parallel.bending_columns());
      EXPECT_EQ(serial.bending_values(), parallel.bending_values());
    }
}
