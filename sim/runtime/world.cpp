// Building the immutable scene snapshot the sim thread publishes after each tick.
#include "sim/runtime/world.hpp"

namespace drape::sim {

void fill_snapshot(const World& world, SceneSnapshot& snap) {
  const Cloth& c = world.cloth;
  const auto& st = c.state;
  const size_t n = c.num_vertices();
  snap.sim_time = st.time;
  snap.filled_at = std::chrono::steady_clock::now();
  snap.topology_version = c.topology_version;

  snap.positions.resize(n);
  snap.material.resize(n);
  snap.flags.assign(st.flags.begin(), st.flags.end());
  for (size_t i = 0; i < n; ++i) {
    snap.positions[i] = st.x[i].cast<float>();
    snap.material[i] = c.topo.material[i].cast<float>();
  }
  // Area-weighted vertex normals: the un-normalised triangle normal (twice its area) summed.
  snap.normals.assign(n, Vec3f::Zero());
  snap.indices.resize(c.topo.triangles.size() * 3);
  for (size_t t = 0; t < c.topo.triangles.size(); ++t) {
    const auto& tri = c.topo.triangles[t];
    const Vec3 fn = (st.x[tri[1]] - st.x[tri[0]]).cross(st.x[tri[2]] - st.x[tri[0]]);
    const Vec3f fnf = fn.cast<float>();
    for (int k = 0; k < 3; ++k) {
      snap.normals[tri[k]] += fnf;
      snap.indices[3 * t + k] = static_cast<uint32_t>(tri[k]);
    }
  }
  for (Vec3f& nm : snap.normals) {
    const float len = nm.norm();
    nm = len > 0 ? Vec3f(nm / len) : Vec3f(0, 1, 0);
  }
  snap.strain.clear();

  snap.form = world.scene.form;
  snap.plates = world.scene.plates;
  snap.boxes = world.scene.boxes;
  snap.spheres = world.scene.spheres;
  snap.hands = world.scene.hands;

  snap.pins.clear();
  for (size_t i = 0; i < n; ++i) {
    if (st.flags[i] & kFlagPinned) snap.pins.push_back(st.x[i].cast<float>());
  }
  snap.candidate_vertex = {-1, -1};
  snap.candidate_point = {Vec3f::Zero(), Vec3f::Zero()};
  snap.candidate_is_form = {false, false};
  snap.cut_strokes.clear();
  snap.cut_strokes_material.clear();
  snap.pattern_outlines.clear();

  snap.solver = world.solver ? world.solver->name() : std::string("none");
  snap.messages.assign(world.messages.begin(), world.messages.end());
  if (world.decorate_snapshot) world.decorate_snapshot(world, snap);
}

}  // namespace drape::sim
