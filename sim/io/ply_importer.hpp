// The Stanford PLY reader the mesh loader hands assimp in place of assimp's own PLY importer.
// assimp 5.2's PLY parser hangs on header lines outside the format's grammar and allocates
// what a count claims before comparing it with the file (fuzz_mesh_ply: 13.1 GB from an ASCII
// body under a well-formed header; binary list counts of billions were never checked). This
// one holds the header to the grammar and never allocates from a count before checking it
// against the bytes left, so its memory stays bounded by the file's size.
#pragma once

#include <assimp/BaseImporter.h>

#include <memory>

namespace drape::sim {

// A new PLY importer for Assimp::Importer::RegisterLoader (which takes ownership). It reads
// "format ascii|binary_little_endian|binary_big_endian 1.0"; the element "vertex" with the
// scalar properties x, y, z (any of the PLY scalar types and their sized aliases), optionally
// nx ny nz and a texture coordinate (s t, u v or texture_u texture_v); the element "face" with
// a list "vertex_indices" or "vertex_index" (any count and index type) into one mesh of
// polygons over the file's vertices (the loader triangulates). Other elements and properties
// are skipped by their declared size (binary) or token count (ascii); comment and obj_info
// lines are ignored. Faces of one or two corners (points, lines) are skipped: the loader drops
// them. Every malformed input is an error (an exception, which assimp reports as the import
// error) naming the header line, or the element, entry and property: a line outside the
// grammar, a count beyond what remains of the file, an index out of range, a token that is not
// a number, a file cut short, data after the last element, a face of no corners, no face.
std::unique_ptr<Assimp::BaseImporter> make_ply_importer();

}  // namespace drape::sim
