// Load speed of the project's PLY importer against assimp 5.2's, on one grid of N^2 vertices
// and (N-1)^2 quads (default 128^2) written as ASCII and as binary little-endian PLY. The
// project's side is the mesh loader (load_mesh_from_memory: import, validation, triangulation,
// joining identical vertices, conversion to a TriMesh); assimp's side an Assimp::Importer with
// its default importers (its PLY importer claims ".ply") and the same post-processing steps,
// without the conversion. Best of --reps loads each; both must give the same vertex and
// triangle counts. Writes out/bench/ply.csv and prints the table.
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <assimp/Importer.hpp>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "bench/best_time.hpp"
#include "sim/io/mesh_io.hpp"

using namespace drape::sim;

namespace {

using drape::bench::best_ms;

template <class T>
void put(std::string& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));  // the machine is little-endian (x86-64)
  out.append(b, sizeof(T));
}

// The grid in the unit square (z a gentle bump), as "ascii" or "binary_little_endian".
std::string grid_ply(int n, bool ascii) {
  std::string out = std::string("ply\nformat ") + (ascii ? "ascii" : "binary_little_endian") +
                    " 1.0\nelement vertex " + std::to_string(n * n) +
                    "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                    std::to_string((n - 1) * (n - 1)) +
                    "\nproperty list uchar int vertex_indices\nend_header\n";
  char line[96];
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const float x = float(i) / float(n - 1), y = float(j) / float(n - 1), z = 0.1f * x * y;
      if (!ascii) {
        put(out, x), put(out, y), put(out, z);
        continue;
      }
      std::snprintf(line, sizeof(line), "%.7g %.7g %.7g\n", x, y, z);
      out += line;
    }
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int a = j * n + i, q[4] = {a, a + 1, a + n + 1, a + n};
      if (!ascii) {
        put(out, uint8_t{4});
        for (int v : q) put(out, int32_t{v});
        continue;
      }
      std::snprintf(line, sizeof(line), "4 %d %d %d %d\n", q[0], q[1], q[2], q[3]);
      out += line;
    }
  return out;
}

struct Row {
  std::string format;
  size_t bytes = 0;
  double own_ms = 0, assimp_ms = 0;
  size_t own_v = 0, own_t = 0, assimp_v = 0, assimp_t = 0;
};

Row measure(int n, bool ascii, int reps) {
  Row r;
  r.format = ascii ? "ascii" : "binary_le";
  const std::string ply = grid_ply(n, ascii);
  r.bytes = ply.size();
  r.own_ms = best_ms(reps, [&] {
    auto m = load_mesh_from_memory(ply.data(), ply.size(), "ply", "grid.ply");
    if (!m.ok()) std::printf("own importer: %s\n", m.error().c_str());
    r.own_v = m.ok() ? m->vertices.size() : 0;
    r.own_t = m.ok() ? m->triangles.size() : 0;
  });
  r.assimp_ms = best_ms(reps, [&] {
    Assimp::Importer imp;
    const aiScene* s =
        imp.ReadFileFromMemory(ply.data(), ply.size(),
                               aiProcess_ValidateDataStructure | aiProcess_Triangulate |
                                   aiProcess_JoinIdenticalVertices | aiProcess_SortByPType,
                               "ply");
    if (!s || s->mNumMeshes == 0) std::printf("assimp: %s\n", imp.GetErrorString());
    r.assimp_v = s && s->mNumMeshes ? s->mMeshes[0]->mNumVertices : 0;
    r.assimp_t = s && s->mNumMeshes ? s->mMeshes[0]->mNumFaces : 0;
  });
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"PLY load speed: the project's importer against assimp's (out/bench/ply.csv)."};
  int n = 128, reps = 5;
  app.add_option("--size", n, "grid vertices a side")->check(CLI::Range(2, 1024));
  app.add_option("--reps", reps, "loads per importer and format (the best is kept)")
      ->check(CLI::Range(1, 100));
  CLI11_PARSE(app, argc, argv);
  std::filesystem::create_directories("out/bench");
  std::ofstream csv("out/bench/ply.csv");
  csv << "grid,format,bytes,own_ms,assimp_ms,assimp_over_own,vertices,triangles\n";
  std::printf("grid %d^2 (%d quads), best of %d\n", n, (n - 1) * (n - 1), reps);
  std::printf("%-10s %10s | %10s %10s %8s | %9s %9s\n", "format", "bytes", "own", "assimp", "ratio",
              "vertices", "triangles");
  bool same = true;
  for (bool ascii : {true, false}) {
    const Row r = measure(n, ascii, reps);
    const bool match = r.own_v == r.assimp_v && r.own_t == r.assimp_t && r.own_t > 0;
    same = same && match;
    std::printf("%-10s %10zu | %7.2f ms %7.2f ms %7.2fx | %9zu %9zu%s\n", r.format.c_str(), r.bytes,
                r.own_ms, r.assimp_ms, r.assimp_ms / r.own_ms, r.own_v, r.own_t,
                match ? "" : " (MISMATCH with assimp's counts)");
    csv << n << ',' << r.format << ',' << r.bytes << ',' << r.own_ms << ',' << r.assimp_ms << ','
        << r.assimp_ms / r.own_ms << ',' << r.own_v << ',' << r.own_t << '\n';
  }
  std::printf("wrote out/bench/ply.csv\n");
  return same ? 0 : 1;
}
