// `drape pattern`: the geometric draping pipeline from a design file to printable patterns.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "sim/core/fabric.hpp"
#include "sim/draping/bodice.hpp"
#include "sim/draping/garment_sim.hpp"
#include "sim/draping/pattern_pipeline.hpp"
#include "sim/form/dress_form.hpp"
#include "sim/form/vit_measurements.hpp"
#include "sim/io/mesh_io.hpp"
#include "xr_app/command.hpp"
#include "xr_app/garment_view.hpp"
#include "xr_app/output_files.hpp"
#include "xr_app/paths.hpp"

namespace {

void print_checks(const std::vector<drape::sim::FitCheck>& checks) {
  for (const auto& c : checks)
    std::printf("  %-4s %-44s %10.2f vs %10.2f: error %+8.3f %s (bound +-%.0f %s)\n",
                c.pass ? "pass" : "FAIL", c.name.c_str(), c.value, c.target, c.error,
                c.unit.c_str(), c.bound, c.unit.c_str());
}

void print_bodice(const drape::sim::BodiceReport& r) {
  std::printf("bodice %s on form %s (ease %.1f mm)\n", r.design.c_str(), r.form.c_str(), r.ease_mm);
  for (const auto& p : r.pieces) {
    std::printf(
        "  %-13s waist dart %.1f mm (legs %.1f/%.1f), shoulder dart %.1f mm (legs %.1f/%.1f); "
        "side %.1f, shoulder %.1f, armhole %.1f, neckline %.1f mm; strain rms %.2f %%\n",
        p.name.c_str(), p.waist_dart_mm, p.waist_dart_legs_mm[0], p.waist_dart_legs_mm[1],
        p.shoulder_dart_mm, p.shoulder_dart_legs_mm[0], p.shoulder_dart_legs_mm[1], p.side_mm,
        p.shoulder_mm, p.armhole_mm, p.neckline_mm, p.rms_strain_pct);
    std::printf("  %-13s fairness (largest turn per mm):", p.name.c_str());
    for (const auto& [label, f] : p.fairness_deg_per_mm) std::printf(" %s %.2f", label.c_str(), f);
    std::printf(" deg/mm\n");
  }
  std::printf("  seams front - back: side %+.2f mm, shoulder %+.2f mm\n", r.side_seam_mismatch_mm,
              r.shoulder_seam_mismatch_mm);
  print_checks(r.checks);
}

// What --simulate needs besides the pipeline's result: the form (shared with the solver's scene),
// how a scene file names it, the fabric and the solver's limits.
struct SimulateRequest {
  std::shared_ptr<const drape::sim::DressForm> form;
  nlohmann::json scene_form;  // null: no scene file (a form the scene files cannot name)
  drape::sim::FabricParams fabric;
  std::string fabric_name;
  bool fabric_given = false;  // --fabric named it (else the design's)
  drape::sim::GarmentSimOptions options;
};

// A sewn garment simulated on the form (--simulate): garment_sim.gltf, fit_map.png,
// garment_sim.json and garment_scene.json into dir, their names appended to `files`; "" or an
// error naming the file. `ease` (m) is the design's (the girths' section centres).
std::string simulate_garment_files(const std::string& dir, const drape::sim::Garment& garment,
                                   const std::string& name, double ease, const SimulateRequest& rq,
                                   const drape::sim::GarmentSimOptions& options,
                                   std::vector<std::string>& files,
                                   std::optional<drape::sim::GarmentSimResult>* out) {
  namespace ds = drape::sim;
  const ds::MappingSurface surf(*rq.form, ease, true);
  auto sim = ds::simulate_garment(garment, rq.form, surf, rq.fabric, options);
  if (!sim) return sim.error();
  const std::string o = dir + "/";
  ds::TriMesh mesh = ds::garment_to_mesh(garment, name + " (simulated)");
  mesh.vertices = sim->cloth.state.x;
  if (std::string e = ds::write_meshes(o + "garment_sim.gltf", {mesh}); !e.empty()) return e;
  // Without a renderer (a build without one, no Vulkan device) the fit map is left out with a
  // note; the simulation's other files are still written.
  const std::string map_error = drape::app::write_fit_map(o + "fit_map.png", sim->cloth, rq.form);
  if (!map_error.empty())
    std::fprintf(stderr, "drape pattern: note: fit map not written: %s\n", map_error.c_str());
  nlohmann::json j = nlohmann::json::parse(sim->to_json());
  j["design"] = name;
  j["fabric"] = rq.fabric_name;
  std::ofstream f(o + "garment_sim.json");
  f << j.dump(2) << "\n";
  if (!f) return o + "garment_sim.json: write failed";
  if (!rq.scene_form.is_null())
    if (std::string e = drape::app::write_garment_scene(
            o + "garment_scene.json", "garment_sim.gltf", rq.scene_form, *rq.form);
        !e.empty())
      return e;
  for (const char* f : {"garment_sim.gltf", "garment_sim.json"}) files.push_back(f);
  if (map_error.empty()) files.push_back("fit_map.png");
  if (!rq.scene_form.is_null()) files.push_back("garment_scene.json");
  *out = std::move(*sim);
  return "";
}

// The skirt's sewn garment simulated (simulate_garment_files).
std::string simulate_and_write(const std::string& dir, drape::sim::PipelineResult& pr,
                               const SimulateRequest& rq,
                               std::optional<drape::sim::GarmentSimResult>* out) {
  return simulate_garment_files(dir, pr.garment, pr.design.name, pr.design.ease, rq, rq.options,
                                pr.report.files, out);
}

void print_simulation(const drape::sim::GarmentSimResult& s, const std::string& fabric) {
  std::printf(
      "simulated garment (xpbd, %s): %d vertices, %zu seam ties; %d frames (%s), %.1f ms, "
      "%.2f ms/frame\n",
      fabric.c_str(), s.cloth.num_vertices(), s.ties.size(), s.frames,
      s.at_rest ? "at rest" : "NOT at rest", s.wall_ms, s.ms_per_frame);
  std::printf("  seam gap max %.3f mm (start %.3f mm); deepest into the form %.3f mm\n",
              s.seam_gap_max_mm, s.seam_gap_start_mm, s.penetration_max_mm);
  std::printf("  strain max %.2f %%, rms %.2f %%, median %.2f %%, 95th percentile %.2f %%\n",
              s.strain_max_pct, s.strain_rms_pct, s.strain_median_pct, s.strain_p95_pct);
  std::printf("  waist seam %.1f mm below its geometric place\n", s.waist_seam_drop_mm);
  for (const auto* b : {&s.waist, &s.hip, &s.bust}) {
    const char* name = b == &s.waist ? "waist" : b == &s.hip ? "hip" : "bust";
    if (!b->vertices) {
      std::printf("  %-5s (y %.3f m) no cloth there\n", name, b->y);
      continue;
    }
    std::printf(
        "  %-5s (y %.3f m) ease max %.2f mm, mean %.2f mm; girth %.2f mm vs geometric %.2f mm + "
        "2 pi offset = %.2f mm: %+.3f %%\n",
        name, b->y, b->ease_max_mm, b->ease_mean_mm, b->girth_mm, b->girth_geometric_mm,
        b->girth_expected_mm, b->girth_error_pct);
  }
}

// The preset `name` of the project's fabrics.json as the fabric to simulate. false (and a
// message starting with `what`) when the file lacks it.
bool set_fabric(SimulateRequest& rq, const std::string& name, const char* what) {
  auto f = drape::sim::load_fabric(drape::app::asset("fabrics.json").string(), name);
  if (!f) {
    std::fprintf(stderr, "drape pattern: %s %s: %s\n", what, name.c_str(), f.error().c_str());
    return false;
  }
  rq.fabric = *f;
  rq.fabric_name = name;
  return true;
}

// With --simulate and no --fabric: the bodice design's fabric preset. false (and a message)
// when fabrics.json lacks it.
bool take_design_fabric(SimulateRequest& rq, const std::string& name) {
  return rq.fabric_given || set_fabric(rq, name, "--simulate: fabric");
}

// The bodice and the dress (design files of "type" bodice or dress): drape, check, export.
int run_upper_body(const std::string& type, const std::string& design_path,
                   const drape::sim::DressForm& form, const std::string& form_name,
                   const drape::sim::FabricParams& fabric, const std::string& out,
                   const drape::sim::PipelineOptions& opt, SimulateRequest* rq) {
  namespace ds = drape::sim;
  std::ifstream f(design_path);
  std::stringstream ss;
  ss << f.rdbuf();
  std::optional<ds::DressDesign> dress;
  if (type == "dress") {
    auto d = ds::parse_dress_design(ss.str(), design_path, drape::app::asset("designs").string());
    if (!d) return std::fprintf(stderr, "drape pattern: %s\n", d.error().c_str()), 1;
    dress = *d;
  } else {
    auto d = ds::parse_bodice_design(ss.str(), design_path);
    if (!d) return std::fprintf(stderr, "drape pattern: %s\n", d.error().c_str()), 1;
    dress = ds::DressDesign{d->name, *d, {}};
  }
  dress->bodice.form = form_name;
  // --ease, --seam-allowance and --relax-iterations apply to the bodice as to the skirt (opt
  // passes them on); --spacing and the solver flags concern the skirt's panels only.
  if (opt.ease >= 0) dress->bodice.ease = opt.ease;
  if (opt.seam_allowance >= 0) dress->bodice.seam_allowance = opt.seam_allowance;
  if (opt.relax_iterations >= 0) dress->bodice.relax_iterations = opt.relax_iterations;
  if (rq && !take_design_fabric(*rq, dress->bodice.fabric)) return 1;
  auto bodice = ds::drape_bodice(dress->bodice, form);
  if (!bodice) return std::fprintf(stderr, "drape pattern: %s\n", bodice.error().c_str()), 1;
  std::vector<ds::PatternPiece> pieces = bodice->pieces;
  // The cloth to simulate: the bodice, or the bodice and the skirt sewn at the waist.
  ds::Garment garment = bodice->garment;
  std::optional<ds::DressReport> dr;
  if (type == "dress") {
    dress->skirt.form = form_name;
    ds::PipelineOptions skirt_opt = opt;
    skirt_opt.out_dir.clear();  // the dress writes its own files
    skirt_opt.seam_allowance = dress->bodice.seam_allowance;
    auto skirt = ds::run_pattern_pipeline(dress->skirt, form, fabric, skirt_opt);
    if (!skirt) return std::fprintf(stderr, "drape pattern: %s\n", skirt.error().c_str()), 1;
    dr = ds::dress_report(*bodice, *skirt);
    auto g = ds::dress_garment(bodice->garment, skirt->garment);
    if (!g) return std::fprintf(stderr, "drape pattern: %s\n", g.error().c_str()), 1;
    garment = std::move(*g);
    for (ds::PatternPiece pc : skirt->pieces) {
      pc.name = "Skirt " + pc.name;
      pieces.push_back(pc);
    }
  }
  std::vector<std::string> files;
  std::optional<ds::GarmentSimResult> sim;
  const std::string failed = drape::app::write_whole(out, [&](const std::string& dir) {
    files.clear();
    std::vector<std::string> names = {"pattern.svg", "pattern.dxf", "pattern_a4.pdf",
                                      "pattern_letter.pdf", "report.json"};
    const std::string json =
        dr ? ds::dress_report_json(*dr, names) : ds::bodice_report_json(bodice->report, names);
    std::string e = ds::write_pattern_files(dir, pieces, dress->name, dress->bodice.seam_allowance,
                                            json, &files);
    if (!e.empty() || !rq) return e;
    ds::GarmentSimOptions so = rq->options;
    so.waist_band_above = type != "dress";  // a bodice has no cloth below its waist seam
    return simulate_garment_files(dir, garment, dress->name, dress->bodice.ease, *rq, so, files,
                                  &sim);
  });
  if (!failed.empty()) {
    std::fprintf(stderr, "drape pattern: %s (the pattern files already in %s are kept)\n",
                 failed.c_str(), out.c_str());
    return 1;
  }
  print_bodice(bodice->report);
  if (dr) {
    std::printf("dress %s: skirt %s; sewn skirt hip girth %+.3f %%, waist %+.3f %%\n",
                dress->name.c_str(), dr->skirt.design.c_str(),
                dr->skirt.garment_hip_girth_error_pct, dr->skirt.garment_waist_girth_error_pct);
    for (const auto& [k, v] : dr->waist_mismatch_mm)
      std::printf("  waist seam mismatch %s: %+.2f mm\n", k.c_str(), v);
    print_checks(dr->checks);
  }
  std::printf("  wrote %s/{", out.c_str());
  for (size_t i = 0; i < files.size(); ++i) std::printf("%s%s", i ? "," : "", files[i].c_str());
  std::printf("}\n");
  if (sim) print_simulation(*sim, rq->fabric_name);
  return 0;
}

// The options of --simulate; returns --fabric's option (counted: given or not).
CLI::Option* add_simulate_options(CLI::App& cli, bool& simulate, std::string& fabric,
                                  SimulateRequest& rq) {
  cli.add_flag("--simulate", simulate,
               "also drape the sewn garment on the form with the solver (XPBD) and write "
               "garment_sim.gltf, fit_map.png, garment_sim.json, garment_scene.json");
  auto* o_fabric = cli.add_option("--fabric", fabric,
                                  "with --simulate: the fabric preset (default: the design's)")
                       ->default_str("")
                       ->type_name("NAME");
  cli.add_option("--sim-frames", rq.options.max_frames,
                 "with --simulate: frames (1/90 s) at most before rest")
      ->type_name("N")
      ->check(CLI::Range(1, 100000));
  return o_fabric;
}

// Fills what --simulate needs: the fabric (`fabric_name` when given, else the design's), the
// form shared with the solver and how a scene file names it. false (and a message) on a bad
// fabric.
bool prepare_simulate(SimulateRequest& rq, const drape::sim::DressForm& form,
                      const drape::sim::FabricParams& design_fabric,
                      const std::string& design_fabric_name, const std::string& fabric_name,
                      const std::string& mesh, const std::string& vit,
                      const std::string& form_name) {
  rq.fabric = design_fabric;
  rq.fabric_name = design_fabric_name;
  if (!fabric_name.empty()) {
    if (!set_fabric(rq, fabric_name, "--fabric")) return false;
    rq.fabric_given = true;
  }
  rq.form = std::make_shared<const drape::sim::DressForm>(form);
  namespace fs = std::filesystem;
  if (!mesh.empty())
    rq.scene_form = {{"mesh", fs::absolute(mesh).string()}};
  else if (vit.empty())  // a .vit form has no scene file form: no scene file then
    rq.scene_form = form_name.find(".json") != std::string::npos
                        ? nlohmann::json{{"measurements", fs::absolute(form_name).string()}}
                        : nlohmann::json{{"size", form_name}};
  return true;
}

int run_pattern(int argc, char** argv) {
  std::string design = "tight-skirt", form_name = "9AR", out = "out/pattern", mesh, vit;
  drape::sim::PipelineOptions opt;
  double ease_mm = 0, seam_mm = 0, spacing_mm = 0;
  CLI::App cli{
      "Drapes the design's panels on the form, extracts the pattern, sews the garment and\n"
      "writes pattern.svg, pattern.dxf, pattern_a4.pdf, pattern_letter.pdf,\n"
      "draped_panels.gltf, garment.gltf and report.json into DIR.",
      "drape pattern"};
  cli.option_defaults()->always_capture_default();
  cli.add_option("--design", design, "a design of assets/designs/ by name, or a design file")
      ->type_name("NAME|FILE.json");
  auto* o_form = cli.add_option("--form", form_name, "standard size or measurements file")
                     ->type_name("9AR|FILE.json");
  auto* o_mesh = cli.add_option("--mesh", mesh,
                                "a scanned or modelled form (OBJ, PLY, STL, glTF; as drape form)")
                     ->type_name("FILE");
  auto* o_vit =
      cli.add_option("--vit", vit, "a form from Seamly2D/Valentina individual measurements")
          ->type_name("FILE.vit");
  o_form->excludes(o_mesh)->excludes(o_vit);
  o_mesh->excludes(o_vit);
  cli.add_option("--out", out, "output directory")->type_name("DIR");
  // Without these the design's own values apply.
  auto* o_ease = cli.add_option("--ease", ease_mm, "ease in mm (default: the design's)")
                     ->default_str("")
                     ->type_name("MM")
                     ->check(CLI::Range(0.0, 1000.0));
  auto* o_seam = cli.add_option("--seam-allowance", seam_mm,
                                "print seam allowance in mm (default: the design's)")
                     ->default_str("")
                     ->type_name("MM")
                     ->check(CLI::Range(0.0, 1000.0));
  auto* o_spacing =
      cli.add_option("--spacing", spacing_mm, "panel grid spacing in mm (default: the design's)")
          ->default_str("")
          ->type_name("MM")
          ->check(drape::app::positive_up_to(1000));
  cli.add_option("--relax-iterations", opt.relax_iterations,
                 "relaxation iterations (default: the design's)")
      ->default_str("")
      ->type_name("N")
      ->check(CLI::Range(0, 1000000));
  cli.add_flag("--static-solver", opt.use_static_solver,
               "relax with the static Newton solver instead of Gauss-Seidel");
  bool no_grain = false;
  cli.add_flag("--no-grain-control", no_grain, "do not keep the grain lines straight");
  bool simulate = false;
  std::string sim_fabric;
  SimulateRequest rq;
  auto* o_fabric = add_simulate_options(cli, simulate, sim_fabric, rq);
  if (int rc = drape::app::parse_command_line(cli, argc, argv); rc >= 0) return rc;
  if (o_fabric->count() && !simulate) {
    std::fprintf(stderr, "drape pattern: --fabric: needs --simulate\n");
    return 1;
  }
  if (o_ease->count()) opt.ease = ease_mm / 1000.0;
  if (o_seam->count()) opt.seam_allowance = seam_mm / 1000.0;
  if (o_spacing->count()) opt.spacing = spacing_mm / 1000.0;
  if (no_grain) opt.grain_control = false;
  std::string design_path = design;
  if (design_path.find('/') == std::string::npos && design_path.find(".json") == std::string::npos)
    design_path = drape::app::asset("designs/" + design + ".json").string();
  auto type = drape::sim::design_type(design_path);
  if (!type) {
    std::fprintf(stderr, "drape pattern: %s\n", type.error().c_str());
    return 1;
  }
  auto d = *type == "skirt" ? drape::sim::load_design(design_path)
                            : drape::sim::Result<drape::sim::Design>(drape::sim::Design{});
  if (!d) {
    std::fprintf(stderr, "drape pattern: %s\n", d.error().c_str());
    return 1;
  }
  drape::sim::Result<drape::sim::DressForm> form = drape::sim::Error{"no form"};
  if (!mesh.empty()) {
    // A scanned form: its reference lines are found on it (docs/dress-form.md) and checked
    // before any cloth is draped.
    form = drape::sim::form_from_mesh_file(mesh);
    if (!form) {
      std::fprintf(stderr, "drape pattern: --mesh: %s\n", form.error().c_str());
      return 1;
    }
    if (std::string e = drape::sim::check_reference_lines(*form, mesh); !e.empty()) {
      std::fprintf(stderr, "drape pattern: --mesh: %s\n", e.c_str());
      return 1;
    }
    d->form = std::filesystem::path(mesh).stem().string();
  } else {
    auto m = !vit.empty() ? drape::sim::load_vit(vit)
             : form_name.find(".json") != std::string::npos
                 ? drape::sim::load_measurements(form_name)
                 : drape::sim::measurements_for_size(form_name, drape::app::asset("forms"));
    if (!m) {
      std::fprintf(stderr, "drape pattern: %s: %s\n", vit.empty() ? "--form" : "--vit",
                   m.error().c_str());
      return 1;
    }
    form = drape::sim::DressForm::from_measurements(*m);
    if (!form) {
      std::fprintf(stderr, "drape pattern: %s: %s\n", vit.empty() ? "--form" : "--vit",
                   form.error().c_str());
      return 1;
    }
    d->form = m->size;
  }
  drape::sim::FabricParams fabric;
  if (auto f = drape::sim::load_fabric(drape::app::asset("fabrics.json").string(), d->fabric))
    fabric = *f;
  else
    std::fprintf(stderr, "drape pattern: note: %s; using the default muslin\n", f.error().c_str());
  if (simulate && !prepare_simulate(rq, *form, fabric, d->fabric,
                                    o_fabric->count() ? sim_fabric : "", mesh, vit, form_name))
    return 1;
  if (*type != "skirt")
    return run_upper_body(*type, design_path, *form, d->form, fabric, out, opt,
                          simulate ? &rq : nullptr);
  std::optional<drape::sim::GarmentSimResult> sim;
  // The pattern's files replace those of an earlier run only when every one was written: a full
  // disk leaves the earlier pattern whole (output_files.hpp).
  std::optional<drape::sim::Result<drape::sim::PipelineResult>> r;
  const std::string failed = drape::app::write_whole(out, [&](const std::string& dir) {
    opt.out_dir = dir;
    r = drape::sim::run_pattern_pipeline(*d, *form, fabric, opt);
    if (!*r) return r->error();
    return simulate ? simulate_and_write(dir, **r, rq, &sim) : std::string();
  });
  if (!failed.empty()) {
    std::fprintf(stderr, "drape pattern: %s (the pattern files already in %s are kept)\n",
                 failed.c_str(), out.c_str());
    return 1;
  }
  const auto& rep = (*r)->report;
  std::printf("design %s on form %s (ease %.1f mm), relaxation: %s\n", rep.design.c_str(),
              rep.form.c_str(), rep.ease_mm, rep.relax_backend.c_str());
  std::printf("  outline error before relaxation  %8.4f mm\n", rep.outline_error_before_relax_mm);
  std::printf("  hip widths sum %.2f mm vs hip girth %.2f mm: error %+.3f mm\n",
              rep.hip_width_sum_mm, rep.form_hip_girth_mm + rep.ease_mm, rep.hip_width_error_mm);
  std::printf("  waist widths - intakes %.2f mm vs waist girth %.2f mm: error %+.3f mm\n",
              rep.waist_width_minus_intakes_sum_mm, rep.form_waist_girth_mm + rep.ease_mm,
              rep.waist_width_error_mm);
  std::printf("  piece area vs draped area: worst %.3f %%\n", rep.area_error_pct);
  std::printf("  sewn garment hip girth %.2f mm: error %+.3f %%\n", rep.garment_hip_girth_mm,
              rep.garment_hip_girth_error_pct);
  std::printf("  sewn garment waist girth %.2f mm: error %+.3f %%\n", rep.garment_waist_girth_mm,
              rep.garment_waist_girth_error_pct);
  std::printf(
      "  pattern hip girth %.2f mm (hip widths + slash openings) vs sewn hip line along the "
      "cloth %.2f mm: %+.3f %%\n",
      rep.pattern_hip_girth_mm, rep.garment_hip_line_mm, rep.garment_hip_girth_vs_pattern_pct);
  std::printf("  hem sweep %.1f mm\n", rep.hem_sweep_mm);
  if (rep.flare != "none")
    for (const auto& p : rep.pieces) {
      std::printf("  %-6s slash and spread (%s): darts closed, hem opened by", p.name.c_str(),
                  rep.flare.c_str());
      for (double a : p.spread_deg) std::printf(" %.2f deg", a);
      std::printf("; hem %.1f mm\n", p.hem_mm);
    }
  for (const auto& p : rep.pieces) {
    std::printf("  %-6s darts:", p.name.c_str());
    for (size_t k = 0; k < p.dart_intake_mm.size(); ++k)
      std::printf(" %.1f mm (wanted %.1f)", p.dart_intake_mm[k], p.dart_intake_wanted_mm[k]);
    std::printf("  vs (hip-waist)/4 = %.1f mm; grain tilt near darts %.2f deg, kink %.2f deg\n",
                rep.quarter_difference_mm, p.grain_after.max_tilt_near_darts_deg,
                p.grain_after.max_kink_near_darts_deg);
    std::printf("  %-6s fairness (largest turn per mm):", p.name.c_str());
    for (const auto& [label, f] : p.fairness_deg_per_mm) std::printf(" %s %.2f", label.c_str(), f);
    std::printf(" deg/mm\n");
  }
  std::printf(
      "  time: mapping+extraction %.1f ms, relax %.1f ms, remesh %.1f ms, sew %.1f ms, "
      "export %.1f ms, pipeline %.1f ms\n",
      rep.mapping_extraction_ms, rep.relax_ms, rep.remesh_ms, rep.sew_ms, rep.export_ms,
      rep.pipeline_ms);
  std::printf("  wrote %s/{", out.c_str());
  for (size_t i = 0; i < rep.files.size(); ++i)
    std::printf("%s%s", i ? "," : "", rep.files[i].c_str());
  std::printf("}\n");
  if (sim) print_simulation(*sim, rq.fabric_name);
  return 0;
}

}  // namespace

DRAPE_COMMAND(pattern, "drape a design on the form and export its sewing pattern", run_pattern);
