// Fuzz: bytes -> load_mesh_from_memory (assimp, format chosen by the first byte) -> dress form
// by ray casting. Errors are fine; crashes, hangs and leaks are not.
#include <cstddef>
#include <cstdint>

#include "sim/form/dress_form.hpp"
#include "sim/io/mesh_io.hpp"

// assimp 5.2.5 leaks inside some importers on malformed files (e.g. PLY with unknown
// properties); those leaks are assimp's, not ours, and would end every run early.
extern "C" const char* __lsan_default_suppressions() {
  return "leak:libassimp.so\n";
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 2) return 0;
  static const char* const kHints[] = {"obj", "ply", "stl", "glb"};
  const char* hint = kHints[data[0] % 4];
  auto mesh = drape::sim::load_mesh_from_memory(data + 1, size - 1, hint, "fuzz");
  if (!mesh.ok() || mesh->triangles.size() > 20000) return 0;
  drape::sim::MeshImportOptions opt;
  opt.section_spacing = 0.02;
  auto form = drape::sim::DressForm::from_triangles(*mesh, opt, "fuzz");
  if (form.ok()) (void)form->girth_at(form->landmarks().waist_y);
  return 0;
}
