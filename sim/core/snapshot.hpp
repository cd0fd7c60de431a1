// Immutable picture of the scene published by the simulation thread after each tick: what the
// renderer, the app and tests read. Floats (renderer-ready); built by value, never shared mutably.
#pragma once

#include <Eigen/Core>
#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sim/core/scene_objects.hpp"

namespace drape::sim {

using Vec3f = Eigen::Vector3f;
using Vec2f = Eigen::Vector2f;

struct SimTiming {
  double step_ms_p50 = 0, step_ms_p95 = 0, step_ms_p99 = 0, step_ms_max = 0;
  uint64_t ticks = 0;
  uint64_t missed_ticks = 0;  // ticks whose deadline passed before they started
  double tick_rate_hz = 90;
  int substeps = 1;
};

struct SceneSnapshot {
  uint64_t tick = 0;
  double sim_time = 0;
  uint64_t topology_version = 0;
  // When the sim thread filled it (steady clock): what a consumer's latency is measured from.
  std::chrono::steady_clock::time_point filled_at{};

  // Cloth
  std::vector<Vec3f> positions;
  std::vector<Vec3f> normals;     // area-weighted vertex normals
  std::vector<Vec2f> material;    // (u weft, v warp) in metres: grain lines / check
  std::vector<uint32_t> indices;  // 3 per triangle
  std::vector<uint8_t> flags;     // VertexFlag bits
  std::vector<float> strain;      // optional per-vertex colour value (may be empty)

  // Scene
  std::shared_ptr<const class DressForm> form;  // static: shared, never mutated
  std::vector<Plate> plates;
  std::vector<Box> boxes;
  std::vector<Sphere> spheres;
  std::vector<HandProxy> hands;

  // Interaction display
  std::array<int32_t, 2> candidate_vertex{-1, -1};  // per hand: the particle an op would take
  std::array<Vec3f, 2> candidate_point{Vec3f::Zero(), Vec3f::Zero()};  // or form point (pin)
  std::array<bool, 2> candidate_is_form{false, false};
  // Per hand: every particle an operation could take, best first (layers under the hand), and
  // the fixed particle release would free (-1: none). Filled by the operations.
  std::array<std::vector<int32_t>, 2> candidate_alternatives;
  std::array<int32_t, 2> release_candidate{-1, -1};
  std::vector<Vec3f> pins;                      // pinned particle positions
  std::vector<std::vector<Vec3f>> cut_strokes;  // smoothed strokes (display)
  // The finished cuts' smoothed strokes on the flat cloth (u, v; m): a pattern's cut edges.
  std::vector<std::vector<Vec2f>> cut_strokes_material;
  std::vector<std::vector<Vec2f>> pattern_outlines;  // flattened pattern pieces (m)

  // Status
  std::string solver;
  SimTiming timing;
  std::vector<std::string> messages;  // recent status lines (ignored commands with reasons...)
};

}  // namespace drape::sim
