// The sewn garment in the live session (`drape xr --garment DESIGN`, `drape run --garment`): the
// design's pattern made by the pattern pipeline on the session's form, its pieces sewn, and the
// garment's cloth (the flat pieces its material coordinates, so its triangles rest at their
// pattern shape) put where the pipeline sewed it on the form. The session's solver is XPBD with
// the seams as hard ties (xpbd_ties.hpp) and the settings of `drape pattern --simulate`
// (garment_sim.hpp); the session drapes, pinches, pins and colours the garment (strain, ease)
// on its sim thread as it does the panel, in the headset and in the simulated runtime's window.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "sim/runtime/world.hpp"
#include "sim/solvers/xpbd/solver_xpbd.hpp"
#include "xr_app/app/xr_app.hpp"

namespace drape::app {

// The solver of a live garment: XPBD with `ties`, 20 substeps, double precision, no coarse
// correction (its lattice knows no ties), as simulate_garment runs it.
std::unique_ptr<sim::XpbdSolver> make_garment_solver(std::vector<sim::xpbd::Tie> ties);

// The World of a garment session: opt.garment (a skirt, bodice or dress design file) made into its
// sewn garment on the form of opt.form_* in the fabric opt.garment_fabric (from opt.fabrics_path;
// "" = the design's), the floor, the form's friction, and the solver above. A cut that changes the
// cloth's vertices drops the ties (their indices name the old vertices) and says so in the
// World's messages. Errors name the option and the file ("--garment <file>: ...").
sim::Result<sim::World> make_garment_world(const XrAppOptions& opt);

// The garment's state for the session's log: "garment: tick K: N vertices, T triangles, M seam
// ties, seam gap max G mm, P mm in the form"; "" when the World's solver is not XPBD.
std::string garment_status(const sim::World& w, uint64_t tick);

}  // namespace drape::app
