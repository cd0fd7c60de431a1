// Scenes built by hand for the renderer tests (no simulation): an analytic dress form, a folded
// panel with material coordinates, and the interaction decorations.
#pragma once

#include <memory>

#include "render/renderer.hpp"
#include "sim/core/snapshot.hpp"

namespace drape::render::test {

// An elliptic-section form from y = 0.6 to 1.34 m, centred on the stage origin, with the
// standard landmarks (waist 0.97, hip 0.78, bust 1.15).
std::shared_ptr<const sim::DressForm> analytic_form();
// An nx x ny panel of size w x h in the plane z = z0 (material u along +x, v along +y) with a
// sinusoidal fold of amplitude `fold` in z; its bottom-left corner at (x0, y0).
void add_panel(sim::SceneSnapshot& s, int nx, int ny, float w, float h, float x0, float y0,
               float z0, float fold);
// The full decorated scene of the golden image.
sim::SceneSnapshot decorated_scene();
// Renderer for tests: lavapipe, validation on.
std::unique_ptr<Renderer> make_test_renderer(int samples = 1);

}  // namespace drape::render::test
