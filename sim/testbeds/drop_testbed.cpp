// The standard drop scene (sim/testbeds/drop_testbed.hpp).
#include "sim/testbeds/drop_testbed.hpp"

#include <algorithm>
#include <cmath>

namespace drape::sim {

DropTestbed make_front_drop(std::shared_ptr<const DressForm> form, int n, double size,
                            const FabricParams& fabric, double gap) {
  DropTestbed d;
  d.scene.form = form;
  d.scene.offset = 0.003;
  PanelSpec spec;
  spec.width = spec.height = size;
  spec.nx = spec.ny = std::max(n, 2);
  d.cloth = make_panel(spec, fabric);
  const DressForm& f = *form;
  d.hinge_y = std::min(f.landmarks().bust_y + 0.10, f.max_y() - 0.02);
  // Foremost point of the form at the hinge height (front half of the section).
  double zmax = -1e9;
  for (int k = -64; k <= 64; ++k) {
    const double th = k * (3.14159265358979323846 / 128);
    zmax = std::max(zmax, f.surface_at(d.hinge_y, th).z());
  }
  d.hinge_z = zmax + gap;
  const Vec2 c = f.centre_at(d.hinge_y);
  // Material (u, v) -> origin + u x - v z: the top edge v = size at the hinge, the bottom edge
  // v = 0 `size` m in front of it.
  place_spread(d.cloth, Vec3(c.x() - size / 2, d.hinge_y, d.hinge_z + size), Vec3::UnitX(),
               -Vec3::UnitZ());
  const int nx = d.cloth.topo.grid_nx;
  for (int i = 0; i < nx; ++i)
    d.cloth.state.flags[(d.cloth.topo.grid_ny - 1) * nx + i] |= kFlagPinned;
  d.cloth.relump_masses();
  return d;
}

}  // namespace drape::sim
