// `drape pattern`: the geometric draping pipeline from a design file to printable patterns.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "sim/core/fabric.hpp"
#include "sim/draping/pattern_pipeline.hpp"
#include "sim/form/dress_form.hpp"
#include "xr_app/command.hpp"

namespace {

void usage() {
  std::fprintf(
      stderr,
      "usage: drape pattern --design NAME|FILE.json [--form 9AR|FILE.json] [--out DIR]\n"
      "                     [--ease MM] [--seam-allowance MM] [--spacing MM]\n"
      "                     [--relax-iterations N] [--static-solver] [--no-grain-control]\n"
      "Drapes the design's panels on the form, extracts the pattern, sews the garment and\n"
      "writes pattern.svg, pattern.dxf, pattern_a4.pdf, pattern_letter.pdf,\n"
      "draped_panels.gltf, garment.gltf and report.json into DIR (out/pattern/).\n");
}

bool parse_mm(const char* s, double* out) {
  char* end = nullptr;
  const double v = std::strtod(s, &end);
  if (!end || *end || !(v >= 0) || v > 1000) return false;
  *out = v / 1000.0;
  return true;
}

int run_pattern(int argc, char** argv) {
  std::string design = "tight-skirt", form_name = "9AR", out = "out/pattern";
  drape::sim::PipelineOptions opt;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has = i + 1 < argc;
    if (a == "--help" || a == "-h") {
      usage();
      return 0;
    } else if (a == "--design" && has) {
      design = argv[++i];
    } else if (a == "--form" && has) {
      form_name = argv[++i];
    } else if (a == "--out" && has) {
      out = argv[++i];
    } else if (a == "--ease" && has) {
      if (!parse_mm(argv[++i], &opt.ease)) {
        std::fprintf(stderr,
                     "drape pattern: --ease: expected millimetres within 0..1000, got '%s'\n",
                     argv[i]);
        return 2;
      }
    } else if (a == "--seam-allowance" && has) {
      if (!parse_mm(argv[++i], &opt.seam_allowance)) {
        std::fprintf(stderr, "drape pattern: --seam-allowance: expected millimetres, got '%s'\n",
                     argv[i]);
        return 2;
      }
    } else if (a == "--spacing" && has) {
      if (!parse_mm(argv[++i], &opt.spacing) || opt.spacing <= 0) {
        std::fprintf(stderr, "drape pattern: --spacing: expected positive millimetres, got '%s'\n",
                     argv[i]);
        return 2;
      }
    } else if (a == "--relax-iterations" && has) {
      opt.relax_iterations = std::atoi(argv[++i]);
    } else if (a == "--static-solver") {
      opt.use_static_solver = true;
    } else if (a == "--no-grain-control") {
      opt.grain_control = false;
    } else {
      std::fprintf(stderr, "drape pattern: unknown or incomplete option '%s'\n", a.c_str());
      usage();
      return 2;
    }
  }
  const std::string root = DRAPE_SOURCE_DIR;
  std::string design_path = design;
  if (design_path.find('/') == std::string::npos && design_path.find(".json") == std::string::npos)
    design_path = root + "/assets/designs/" + design + ".json";
  auto d = drape::sim::load_design(design_path);
  if (!d) {
    std::fprintf(stderr, "drape pattern: %s\n", d.error().c_str());
    return 1;
  }
  auto m = form_name.find(".json") != std::string::npos
               ? drape::sim::load_measurements(form_name)
               : drape::sim::measurements_for_size(form_name);
  if (!m) {
    std::fprintf(stderr, "drape pattern: --form: %s\n", m.error().c_str());
    return 1;
  }
  auto form = drape::sim::DressForm::from_measurements(*m);
  if (!form) {
    std::fprintf(stderr, "drape pattern: --form: %s\n", form.error().c_str());
    return 1;
  }
  d->form = m->size;
  drape::sim::FabricParams fabric;
  if (auto f = drape::sim::load_fabric(root + "/assets/fabrics.json", d->fabric))
    fabric = *f;
  else
    std::fprintf(stderr, "drape pattern: note: %s; using the default muslin\n", f.error().c_str());
  opt.out_dir = out;
  auto r = drape::sim::run_pattern_pipeline(*d, *form, fabric, opt);
  if (!r) {
    std::fprintf(stderr, "drape pattern: %s\n", r.error().c_str());
    return 1;
  }
  const auto& rep = r->report;
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
  for (const auto& p : rep.pieces) {
    std::printf("  %-6s darts:", p.name.c_str());
    for (size_t k = 0; k < p.dart_intake_mm.size(); ++k)
      std::printf(" %.1f mm (wanted %.1f)", p.dart_intake_mm[k], p.dart_intake_wanted_mm[k]);
    std::printf("  vs (hip-waist)/4 = %.1f mm; grain tilt near darts %.2f deg, kink %.2f deg\n",
                rep.quarter_difference_mm, p.grain_after.max_tilt_near_darts_deg,
                p.grain_after.max_kink_near_darts_deg);
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
  return 0;
}

}  // namespace

DRAPE_COMMAND(pattern, "drape a design on the form and export its sewing pattern", run_pattern);
