// The standard drop scene of the simulation core, shared by the drop test, the baseline
// benchmark and the headless run: a muslin panel held at its top edge in front of the form's
// upper chest, released horizontal, so it swings down and falls against the bust and the front
// of the form. Every vertex stays inside the form's section range (between its bottom and the
// neck base), where the radial section model describes the surface: no part of the panel rests
// on the open top of the model (see docs/sim-core.md, "Drop scene").
#pragma once

#include <memory>

#include "sim/core/cloth.hpp"
#include "sim/core/scene_objects.hpp"
#include "sim/form/dress_form.hpp"

namespace drape::sim {

struct DropTestbed {
  Cloth cloth;
  SceneObjects scene;
  double hinge_y = 0, hinge_z = 0;  // the held top edge (m)
};

// `n` x `n` vertices over a `size` x `size` m panel of `fabric`; the top edge (v = size, the
// grain vertical once hanging) is pinned `gap` m in front of the form's foremost point at the
// height bust + 0.10 m, the panel lying horizontal toward +z. Offset 3 mm, floor on.
DropTestbed make_front_drop(std::shared_ptr<const DressForm> form, int n, double size = 0.4,
                            const FabricParams& fabric = FabricParams{}, double gap = 0.02);

}  // namespace drape::sim
