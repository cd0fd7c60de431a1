// Bullet soft-body peer on the hanging sheet (see bullet_peer.hpp for the matching).
#include "bench/bullet_peer.hpp"

#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <utility>

#include "sim/testbeds/testbed.hpp"

namespace drape::bench {

using drape::sim::Vec2;
using drape::sim::Vec3;

PeerRow run_bullet_sheet(int res, int substeps, int iterations) {
  return run_bullet_sheet(res, substeps, iterations, PeerOptions{});
}

namespace {

// Bullet's world objects, torn down in reverse order of construction.
struct BulletWorld {
  btSoftBodyRigidBodyCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btSoftRigidDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
  std::unique_ptr<btSoftBody> body;
  ~BulletWorld() {
    if (body) world.removeSoftBody(body.get());
  }
};

}  // namespace

PeerRow run_bullet_sheet(int res, int substeps, int iterations, const PeerOptions& opt) {
  substeps = std::max(1, substeps);
  iterations = std::max(1, iterations);
  PeerRow row;
  row.resolution = res;
  const double frame = 1.0 / 90;
  const double h = frame / substeps;
  row.dt = h;
  row.iterations = iterations;

  sim::Testbed sc = sim::make_hanging_sheet(res);
  const sim::Cloth& cloth = sc.cloth;
  const int n = cloth.num_vertices();
  const auto& fab = cloth.fabric;

  auto bw = std::make_unique<BulletWorld>();
  btSoftBodyWorldInfo& wi = bw->world.getWorldInfo();
  const btVector3 g(0, static_cast<btScalar>(-sim::kGravity), 0);
  bw->world.setGravity(g);
  wi.m_gravity = g;
  wi.air_density = 0;
  wi.water_density = 0;
  wi.m_broadphase = &bw->broadphase;
  wi.m_dispatcher = &bw->dispatcher;
  wi.m_sparsesdf.Initialize();

  std::vector<btVector3> xs(n);
  std::vector<btScalar> ms(n);
  for (int i = 0; i < n; ++i) {
    const Vec3& p = cloth.state.x[i];
    xs[i] = btVector3(static_cast<btScalar>(p.x()), static_cast<btScalar>(p.y()),
                      static_cast<btScalar>(p.z()));
    ms[i] = cloth.is_free(i) ? static_cast<btScalar>(cloth.state.mass[i]) : btScalar(0);
  }
  bw->body = std::make_unique<btSoftBody>(&wi, n, xs.data(), ms.data());
  btSoftBody* sb = bw->body.get();
  btSoftBody::Config& cfg = sb->m_cfg;
  cfg.kDP = static_cast<btScalar>(opt.kdp);
  cfg.kDG = 0;
  cfg.kLF = 0;
  cfg.drag = 0;
  cfg.kMT = 0;
  cfg.piterations = iterations;
  cfg.viterations = 0;
  cfg.diterations = 0;
  cfg.collisions = 0;  // no rigid/soft/self collision: the scene has no obstacle

  // One link per triangle edge, stiffness from the FEM along the edge.
  std::map<std::pair<int, int>, int> edges;
  for (const auto& t : cloth.topo.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = std::min(t[k], t[(k + 1) % 3]), b = std::max(t[k], t[(k + 1) % 3]);
      edges.emplace(std::make_pair(a, b), 0);
    }
  const auto& M = cloth.topo.material;
  auto derived_klst = [&](double k, int a, int b) {
    if (opt.klst_fixed > 0) return std::min(1.0, opt.klst_fixed);
    const double ima = cloth.is_free(a) ? 1.0 / cloth.state.mass[a] : 0.0;
    const double imb = cloth.is_free(b) ? 1.0 / cloth.state.mass[b] : 0.0;
    if (ima + imb <= 0) return 1.0;
    const double m_ab = 1.0 / (ima + imb);
    const double s = k * h * h / (m_ab + k * h * h);
    const double kl = 1.0 - std::pow(1.0 - s, 1.0 / iterations);
    return std::clamp(kl * opt.klst_scale, 0.0, 1.0);
  };
  for (const auto& [e, unused] : edges) {
    (void)unused;
    const auto [a, b] = e;
    const Vec2 d = M[b] - M[a];
    const double len = d.norm();
    if (len <= 0) continue;
    const double cu = d.x() / len, cv = d.y() / len;
    double k;
    if (std::abs(cu) > 0.999) {
      k = fab.stretch_weft;  // along u: weft
    } else if (std::abs(cv) > 0.999) {
      k = fab.stretch_warp;
    } else {
      k = 2.0 * fab.shear;  // one diagonal per cell: G = k_d / 2 on a square cell
    }
    btSoftBody::Material* mat = sb->appendMaterial();
    mat->m_kLST = static_cast<btScalar>(derived_klst(k, a, b));
    mat->m_kAST = 0;
    mat->m_kVST = 0;
    sb->appendLink(a, b, mat);
    sb->m_links[sb->m_links.size() - 1].m_rl = static_cast<btScalar>(len);
  }
  if (opt.bending) {
    // Bullet's bending: links between vertices two edges apart. A distance-2 link across a
    // hinge resists the fold; its kLST from a spring k = B / L^2 per unit width (rough).
    btSoftBody::Material* mb = sb->appendMaterial();
    const double sp = cloth.topo.spacing > 0 ? cloth.topo.spacing : 0.5 / (res - 1);
    const double kb = fab.bending_warp / (sp * sp);
    double mavg = 0;
    for (int i = 0; i < n; ++i) mavg += cloth.state.mass[i];
    mavg /= n;
    const double s = kb * h * h / (0.5 * mavg + kb * h * h);
    mb->m_kLST = static_cast<btScalar>(1.0 - std::pow(1.0 - s, 1.0 / iterations));
    mb->m_kAST = mb->m_kVST = 0;
    sb->generateBendingConstraints(2, mb);
  }
  bw->world.addSoftBody(sb);

  const int frames = static_cast<int>(std::lround(sc.duration / frame));
  const auto t0 = std::chrono::steady_clock::now();
  for (int f = 0; f < frames && row.stable; ++f) {
    for (int s = 0; s < substeps; ++s) bw->world.stepSimulation(static_cast<btScalar>(h), 0);
    const btVector3& p = sb->m_nodes[0].m_x;
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) row.stable = false;
  }
  const double ms_total =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  row.ms_per_frame = ms_total / frames;
  row.positions.resize(n);
  for (int i = 0; i < n; ++i) {
    const btVector3& p = sb->m_nodes[i].m_x;
    row.positions[i] = Eigen::Vector3d(p.x(), p.y(), p.z());
    if (!row.positions[i].allFinite() || (row.positions[i] - cloth.state.x[i]).norm() > 50.0)
      row.stable = false;
  }
  return row;
}

}  // namespace drape::bench
