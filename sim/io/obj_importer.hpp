// The Wavefront OBJ reader the mesh loader hands assimp in place of assimp's own OBJ importer.
// assimp 5.2's importer fills a 16 MiB line cache and a 16 MiB line buffer for every file, however
// small (about 14 ms a call under AddressSanitizer, 59 calls a second in fuzz_mesh_obj), and it
// also runs on any file of another format that no importer claims and that holds a token such
// as "v " or "f " in its first 200 bytes. This one reads the geometry the product uses.
#pragma once

#include <assimp/BaseImporter.h>

#include <memory>

namespace drape::sim {

// A new OBJ importer for Assimp::Importer::RegisterLoader (which takes ownership). It reads
// "v x y z", "vt u [v]", "vn x y z" and "f" lines (corners "v", "v/t", "v//n", "v/t/n", 1-based
// or negative, relative to the end) into one mesh of polygons, a vertex per face corner (the
// importer's JoinIdenticalVertices step merges them). Faces of one or two corners (points,
// lines) and the lines "l" and "p" are skipped: the loader drops points and lines. Comments,
// empty lines and the other statements (o, g, s, usemtl, mtllib, ...) are ignored. A number
// that does not parse, an index of 0 or out of range, or a file without a face is an error
// (an exception naming the line, which assimp reports as the import error).
std::unique_ptr<Assimp::BaseImporter> make_obj_importer();

}  // namespace drape::sim
