// Tracking benchmark (./drape bench tracking): One-Euro jitter reduction vs added lag on a noisy
// hand trace (30 Hz, 5 mm Kinect-like noise), the Kinect depth pipeline's frames per second
// on 640x480, and per hand source (UDP stream, Kinect depth frames, trace file) the latency from a
// step of the palm to the overlay, the jitter at rest before and after the filter and the CPU
// time per frame (bench/tracking_sources.cpp). Run on one core by bench/tracking.sh. Writes
// out/bench/tracking.json and out/bench/tracking_sources.csv.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <vector>

#include "bench/tracking_sources.hpp"
#include "tracking/kinect.hpp"
#include "tracking/one_euro.hpp"
#include "tracking/trace.hpp"

using namespace drape::tracking;

namespace {
// Ground truth: still 2 s, reach 40 cm in 0.8 s, still 2 s, slow circle, ... repeated.
Vec3 truth(double t) {
  const double c = std::fmod(t, 8.0);
  if (c < 2.0) return Vec3(0, 1.2, -0.5);
  if (c < 2.8) {
    const double s = (c - 2.0) / 0.8, w = s * s * (3 - 2 * s);
    return Vec3(0.4 * w, 1.2, -0.5);
  }
  if (c < 4.8) return Vec3(0.4, 1.2, -0.5);
  if (c < 7.2) {
    const double a = (c - 4.8) / 2.4 * 2 * M_PI;
    return Vec3(0.2 + 0.2 * std::cos(a), 1.2 + 0.2 * std::sin(a), -0.5);
  }
  const double s = (c - 7.2) / 0.8, w = s * s * (3 - 2 * s);
  return Vec3(0.4 * (1 - w), 1.2, -0.5);
}
bool still(double t) {
  const double c = std::fmod(t, 8.0);
  return (c > 0.5 && c < 2.0) || (c > 3.3 && c < 4.8);
}

struct Score {
  double jitter_mm, lag_ms;
};

Score evaluate(const std::vector<double>& ts, const std::vector<Vec3>& y) {
  double j2 = 0;
  int nj = 0;
  for (size_t i = 0; i < ts.size(); ++i)
    if (still(ts[i])) {
      j2 += (y[i] - truth(ts[i])).squaredNorm();
      ++nj;
    }
  // Lag: shift of the truth that best explains the output in moving phases.
  double best = 1e18, lag = 0;
  for (double d = 0; d <= 0.2; d += 0.001) {
    double e = 0;
    for (size_t i = 0; i < ts.size(); ++i)
      if (!still(ts[i]) && ts[i] > 1) e += (y[i] - truth(ts[i] - d)).squaredNorm();
    if (e < best) {
      best = e;
      lag = d;
    }
  }
  return {1000 * std::sqrt(j2 / nj), 1000 * lag};
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "One-Euro jitter vs lag, the Kinect pipeline's frames per second, and per hand source "
      "the step-to-overlay latency, jitter and CPU per frame (out/bench/tracking.json, "
      "out/bench/tracking_sources.csv)."};
  std::string replay;
  app.add_option("--kinect-replay", replay,
                 "internal: the child of the fakenect replay, run under `fakenect DIR` by the "
                 "benchmark itself");
  CLI11_PARSE(app, argc, argv);
  if (!replay.empty()) return drape::bench::run_kinect_replay_child(replay);
  // Noisy trace (also written as a trace file to exercise record/replay).
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 0.005);
  std::vector<double> ts;
  std::vector<Vec3> raw;
  {
    TraceRecorder rec("out/bench/tracking_trace.csv");
    for (int i = 0; i < 30 * 64; ++i) {
      const double t = i / 30.0;
      HandFrame f;
      f.time = t;
      f.tracked = true;
      f.confidence = 1;
      f.palm.position = truth(t) + Vec3(noise(rng), noise(rng), noise(rng));
      if (rec.ok()) rec.write(f);
      ts.push_back(t);
      raw.push_back(f.palm.position);
    }
  }
  const Score r = evaluate(ts, raw);
  nlohmann::json j;
  std::printf("One-Euro on a 30 Hz trace with 5 mm noise (64 s)\n");
  std::printf("%-28s %12s %14s %12s\n", "filter", "jitter (mm)", "reduction", "lag (ms)");
  std::printf("%-28s %12.2f %14s %12.1f\n", "raw", r.jitter_mm, "-", r.lag_ms);
  struct P {
    const char* name;
    OneEuroParams p;
  };
  const OneEuroParams def;
  std::vector<P> ps = {{"default (1.0 Hz, beta 2.0)", def},
                       {"min_cutoff 1.0, beta 0.5", {1.0, 0.5, 1.0}},
                       {"min_cutoff 0.5, beta 2.0", {0.5, 2.0, 1.0}},
                       {"min_cutoff 2.0, beta 2.0", {2.0, 2.0, 1.0}},
                       {"min_cutoff 1.0, beta 4.0", {1.0, 4.0, 1.0}},
                       {"min_cutoff 1.0, beta 0 (EMA)", {1.0, 0.0, 1.0}}};
  for (const auto& p : ps) {
    OneEuro f(p.p);
    std::vector<Vec3> y;
    for (size_t i = 0; i < ts.size(); ++i) y.push_back(f.filter(raw[i], ts[i]));
    const Score s = evaluate(ts, y);
    const double red = 1 - s.jitter_mm / r.jitter_mm;
    std::printf("%-28s %12.2f %13.1f%% %12.1f\n", p.name, s.jitter_mm, 100 * red,
                s.lag_ms - r.lag_ms);
    j["filters"][p.name] = {{"jitter_mm", s.jitter_mm},
                            {"jitter_reduction", red},
                            {"added_lag_ms", s.lag_ms - r.lag_ms}};
    if (&p == &ps[0]) {
      j["jitter_reduction"] = red;
      j["added_lag_ms"] = s.lag_ms - r.lag_ms;
      j["jitter_raw_mm"] = r.jitter_mm;
      j["jitter_filtered_mm"] = s.jitter_mm;
    }
  }
  // Kinect pipeline: raw 11-bit 640x480 -> millimetres -> segmentation -> 3D, one thread.
  std::vector<std::vector<uint16_t>> frames;
  DepthIntrinsics k;
  for (int n = 0; n < 8; ++n) {
    std::vector<uint16_t> f(640 * 480);
    const double hu = 200 + 10 * n, hv = 220;
    for (int v = 0; v < 480; ++v)
      for (int u = 0; u < 640; ++u) {
        double z = 2.6;
        if (u > 220 && u < 420 && v > 150) z = 1.6;
        if (std::hypot(u - hu, v - hv) < 0.08 * k.fx / 1.1) z = 1.1;
        if (std::hypot(u - 450, v - 240) < 0.08 * k.fx / 1.15) z = 1.15;
        f[v * 640 + u] = kinect_m_to_raw(z + noise(rng) * 0.5);
      }
    frames.push_back(std::move(f));
  }
  HandSegmenter seg;
  int processed = 0, found = 0;
  const auto t0 = std::chrono::steady_clock::now();
  double el = 0;
  while (el < 3.0) {
    found += static_cast<int>(seg.process_raw11(frames[processed % 8].data(), 640, 480, 0).size());
    ++processed;
    el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  const double fps = processed / el;
  std::printf(
      "\nKinect pipeline 640x480 (raw11 -> mm -> segment -> 3D), one thread: %.0f fps "
      "(%.2f ms/frame, %.2f hands/frame; target >= 30)\n",
      fps, 1000 / fps, double(found) / processed);
  j["kinect_fps"] = fps;
  j["kinect_ms_per_frame"] = 1000 / fps;
  j["sources"] = drape::bench::run_source_benchmarks("out/bench", "out/bench/tracking_sources.csv");
  std::ofstream("out/bench/tracking.json") << j.dump(2) << "\n";
  std::printf("wrote out/bench/tracking.json\n");
  return 0;
}
