// The sewn garment as the live session's cloth (garment_scene.hpp).
#include "xr_app/app/garment_scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "sim/core/fabric.hpp"
#include "sim/draping/bodice.hpp"
#include "sim/draping/garment_sim.hpp"
#include "sim/draping/pattern_pipeline.hpp"
#include "sim/form/dress_form.hpp"
#include "xr_app/app/desk_scene.hpp"
#include "xr_app/paths.hpp"

namespace drape::app {
namespace {

// The fabric of the garment: opt.garment_fabric when given, else the design's `own`; from the
// fabrics file (none: only the built-in muslin).
sim::Result<sim::FabricParams> garment_fabric(const XrAppOptions& opt, const std::string& own) {
  const std::string name = opt.garment_fabric.empty() ? own : opt.garment_fabric;
  const std::string what = opt.garment_fabric.empty()
                               ? "--garment " + opt.garment + ": the design's fabric " + name
                               : "--garment-fabric " + name;
  if (opt.fabrics_path.empty()) {
    if (name == sim::FabricParams{}.name) return sim::FabricParams{};
    return sim::make_error(what, "no fabrics file to find it in");
  }
  auto f = sim::load_fabric(opt.fabrics_path, name);
  if (!f) return sim::make_error(what, f.error());
  return f;
}

// The whole text of the design file opt.garment (xr_launch checked that it exists).
std::string design_text(const XrAppOptions& opt) {
  std::ifstream in(opt.garment, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The bodice design's sewn bodice on `form`: its zones' flat pattern as rest, its darts' legs,
// side and shoulder seams as ties (drape_bodice).
sim::Result<sim::Garment> sewn_bodice(const XrAppOptions& opt, const sim::DressForm& form,
                                      sim::FabricParams& fabric) {
  auto d = sim::parse_bodice_design(design_text(opt), opt.garment);
  if (!d) return sim::make_error("--garment", d.error());
  auto f = garment_fabric(opt, d->fabric);
  if (!f) return sim::Error{f.error()};
  fabric = *f;
  auto b = sim::drape_bodice(*d, form);
  if (!b) return sim::make_error("--garment " + opt.garment, b.error());
  return std::move(b->garment);
}

// The dress design's sewn dress on `form`: its bodice (sewn_bodice's) and its skirt (the
// pattern pipeline's) joined at the waist by ties at equal places along the waist loop
// (dress_garment), as `drape pattern --design dress --simulate` sews it. The dress's fabric is
// its bodice's; its parts are looked up as `drape pattern` looks them up (the designs among the
// assets, or paths).
sim::Result<sim::Garment> sewn_dress(const XrAppOptions& opt, const sim::DressForm& form,
                                     sim::FabricParams& fabric) {
  auto d = sim::parse_dress_design(design_text(opt), opt.garment, asset("designs").string());
  if (!d) return sim::make_error("--garment", d.error());
  auto f = garment_fabric(opt, d->bodice.fabric);
  if (!f) return sim::Error{f.error()};
  fabric = *f;
  const std::string what = "--garment " + opt.garment;
  auto b = sim::drape_bodice(d->bodice, form);
  if (!b) return sim::make_error(what, b.error());
  auto skirt = sim::run_pattern_pipeline(d->skirt, form, fabric);
  if (!skirt) return sim::make_error(what, skirt.error());
  auto g = sim::dress_garment(b->garment, skirt->garment);
  if (!g) return sim::make_error(what, g.error());
  return g;
}

// The design's sewn garment on `form` (the pipeline writes no files).
sim::Result<sim::Garment> sewn_garment(const XrAppOptions& opt, const sim::DressForm& form,
                                       sim::FabricParams& fabric) {
  auto type = sim::design_type(opt.garment);
  if (!type) return sim::make_error("--garment", type.error());
  if (*type == "bodice") return sewn_bodice(opt, form, fabric);
  if (*type == "dress") return sewn_dress(opt, form, fabric);
  auto d = sim::load_design(opt.garment);
  if (!d) return sim::make_error("--garment", d.error());
  auto f = garment_fabric(opt, d->fabric);
  if (!f) return sim::Error{f.error()};
  fabric = *f;
  auto pr = sim::run_pattern_pipeline(*d, form, fabric);
  if (!pr) return sim::make_error("--garment " + opt.garment, pr.error());
  return std::move(pr->garment);
}

// Drops the ties once the cloth's vertices change (a cut or slit renumbers them).
void drop_ties_on_new_topology(sim::World& w, sim::XpbdSolver* solver) {
  const int n0 = w.cloth.num_vertices();
  auto inner = w.before_step;
  w.before_step = [inner, solver, n0](sim::World& world, double dt) {
    if (world.cloth.num_vertices() != n0 && !solver->ties().empty()) {
      world.report("garment: the cloth's vertices changed (" + std::to_string(n0) + " -> " +
                   std::to_string(world.cloth.num_vertices()) + "): its seam ties are dropped");
      solver->set_ties({});
    }
    if (inner) inner(world, dt);
  };
}

}  // namespace

std::unique_ptr<sim::XpbdSolver> make_garment_solver(std::vector<sim::xpbd::Tie> ties) {
  const sim::GarmentSimOptions g;
  sim::XpbdOptions xo = sim::garment_xpbd_options(g);
  // The garment at rest sleeps (its seams join its pieces into one: it sleeps and wakes as a
  // whole) and costs a contact check per tick until a hand or a pin moves it.
  xo.freeze = true;
  xo.rest_holds_at_detection = true;
  auto s = std::make_unique<sim::XpbdSolver>(xo);
  s->set_ties(std::move(ties), g.tie_passes);
  return s;
}

sim::Result<sim::World> make_garment_world(const XrAppOptions& opt) {
  auto form = desk_form(opt);
  if (!form) return sim::Error{form.error()};
  sim::FabricParams fabric;
  auto g = sewn_garment(opt, *form, fabric);
  if (!g) return sim::Error{g.error()};
  sim::World w;
  w.cloth = sim::garment_cloth(*g, fabric);
  if (std::string e = w.cloth.validate(); !e.empty())
    return sim::make_error("--garment " + opt.garment, e);
  w.scene.form = std::make_shared<const sim::DressForm>(std::move(*form));
  w.scene.floor = true;
  const sim::GarmentSimOptions go;
  w.scene.friction = go.friction;
  w.scene.offset = go.contact_offset;
  std::vector<sim::xpbd::Tie> ties;
  for (const sim::SeamTie& t : g->ties) ties.push_back({t.a, t.b0, t.b1, t.t});
  auto solver = make_garment_solver(std::move(ties));
  drop_ties_on_new_topology(w, solver.get());
  w.solver = std::move(solver);
  return w;
}

std::string garment_status(const sim::World& w, uint64_t tick) {
  const auto* s = dynamic_cast<const sim::XpbdSolver*>(w.solver.get());
  if (!s) return "";
  double inside = 0;
  if (w.scene.form)
    for (const sim::Vec3& x : w.cloth.state.x) {
      const double d = w.scene.form->signed_distance(x);
      if (std::isfinite(d)) inside = std::max(inside, -d);
    }
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "garment: tick %llu: %d vertices, %d triangles, %zu seam ties, seam gap max "
                "%.3f mm, %.3f mm in the form, %d vertices asleep",
                static_cast<unsigned long long>(tick), w.cloth.num_vertices(),
                w.cloth.topo.num_triangles(), s->ties().size(),
                sim::xpbd::max_tie_gap(s->ties(), w.cloth.state.x) * 1000, inside * 1000,
                s->frozen_count());
  return buf;
}

}  // namespace drape::app
