// Fuzz: bytes -> load_mesh_from_memory (assimp, the format given by DRAPE_FUZZ_MESH_FORMAT: one
// target per format, fuzz_mesh_obj/_ply/_stl/_glb, each with its own seeds in
// fuzz/corpus/mesh_<format>/) -> dress form by ray casting. Errors are fine; crashes, hangs and
// leaks are not.
#include <cstddef>
#include <cstdint>

#include "sim/form/dress_form.hpp"
#include "sim/io/mesh_io.hpp"

#ifndef DRAPE_FUZZ_MESH_FORMAT
#error "DRAPE_FUZZ_MESH_FORMAT (obj, ply, stl or glb) must be defined"
#endif

// assimp 5.2.5 leaks inside some importers on malformed files (e.g. PLY with unknown
// properties); those leaks are assimp's, not ours, and would end every run early.
extern "C" const char* __lsan_default_suppressions() {
  return "leak:libassimp.so\n";
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  auto mesh = drape::sim::load_mesh_from_memory(data, size, DRAPE_FUZZ_MESH_FORMAT, "fuzz");
  if (!mesh.ok() || mesh->triangles.size() > 20000) return 0;
  drape::sim::MeshImportOptions opt;
  opt.section_spacing = 0.02;
  auto form = drape::sim::DressForm::from_triangles(*mesh, opt, "fuzz");
  if (form.ok()) (void)form->girth_at(form->landmarks().waist_y);
  return 0;
}
