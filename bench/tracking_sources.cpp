// The hand sources as the app's frame loop runs them (xr_app/app/external_hands.cpp): each frame
// the source is polled, each new palm goes through HandFilter, and the hand overlay is drawn at the
// latest filtered palm. The loop runs on a virtual 90 Hz clock so that every source sees the same
// palm path: rests of 2 s and instantaneous 10 cm steps, at the source's own rate (UDP 60 Hz, a
// trace file 60 Hz, the Kinect 30 Hz) with its own noise (2 mm per axis for the UDP and trace
// samples; for the Kinect, depth frames synthesized with 2.5 mm pixel noise and a hand outline
// that moves 1 px and 2 mm per frame, segmented by HandSegmenter as KinectSource's thread does).
// The same depth frames are also written as a fakenect recording and replayed through libfreenect
// into KinectSource, in real time, by a child process run under `fakenect` (a shorter path).
//   latency: frames from the frame in which the source first delivers a sample after the step
//            to the first frame whose overlay has covered 10 % (onset) and 50 % of the step; the
//            app draws a frame's overlay from that frame's pose (pose-to-photon 0 frames,
//            `./drape bench xr`), so these are source-to-photon frames;
//   jitter:  RMS distance (mm) from the window's mean over the last 1.3 s of each rest, of the
//            source's samples (before the filter) and of the overlay per frame (after it);
//   CPU:     thread CPU time per frame of poll + segmentation (Kinect) + filter.
#include "bench/tracking_sources.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <thread>
#include <vector>

#include "tracking/kinect.hpp"
#include "tracking/one_euro.hpp"
#include "tracking/trace.hpp"
#include "tracking/udp_source.hpp"

namespace drape::bench {

using namespace drape::tracking;

namespace {

constexpr double kFrameRate = 90;
constexpr double kStepM = 0.10;  // m
constexpr double kSettle = 0.7;  // s after a step before the rest counts for the jitter
constexpr double kOnset = 0.10;  // share of the step that counts as "shown"
constexpr double kHalf = 0.50;

// The palm's path: `steps` + 1 rests of `rest` seconds with an instantaneous step between two
// points along x (camera frame of the Kinect: in front at z = -1.1 m, left of the image centre
// so that the segmenter always labels it the same hand).
struct Path {
  double rest = 2.0;
  int steps = 8;
  Vec3 at_rest(int i) const { return Vec3(i % 2 == 0 ? -0.25 : -0.25 + kStepM, 0.0, -1.1); }
  Vec3 truth(double t) const { return at_rest(std::min(steps, static_cast<int>(t / rest))); }
  double duration() const { return rest * (steps + 1); }
};
// The fakenect replay's path is shorter: its recording holds 0.6 MB per depth frame.
constexpr Path kPath{2.0, 8}, kReplayPath{1.0, 4};

double cpu_s(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

HandFrame palm_frame(double t, const Vec3& p) {
  HandFrame f;
  f.hand = Hand::Right;
  f.time = t;
  f.tracked = true;
  f.confidence = 0.9;
  f.palm.position = p;
  return f;
}

// A source under test: deliver(t) makes every sample due by t available (outside the timed
// part: it is the tracker's or the sender's work), poll(t) is the app's side (timed).
struct Source {
  std::string name;
  double rate = 0;  // samples per second
  Path path = kPath;
  // Real time (the fakenect replay): the loop sleeps until each frame's time, and the CPU time
  // is the process's (the source's own thread included) over the whole loop.
  bool realtime = false;
  std::function<void(double)> deliver;
  std::function<std::vector<HandFrame>(double)> poll;
  std::vector<double> sample_times;  // when each sample became available
  std::vector<Vec3> samples;         // what the source measured (before the filter)
};

struct Result {
  std::string name;
  double rate = 0;
  double onset_median = -1, onset_max = -1, half_median = -1, half_max = -1;
  double jitter_raw_mm = 0, jitter_filtered_mm = 0;
  double cpu_us_per_frame = 0;
  int steps_seen = 0, steps = 0;
};

double median(std::vector<double> v) {
  if (v.empty()) return -1;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double rms_about_mean(const std::vector<Vec3>& v) {
  if (v.size() < 2) return 0;
  Vec3 mean = Vec3::Zero();
  for (const auto& p : v) mean += p;
  mean /= static_cast<double>(v.size());
  double s = 0;
  for (const auto& p : v) s += (p - mean).squaredNorm();
  return std::sqrt(s / static_cast<double>(v.size()));
}

// The frame loop of external_hands.cpp (on a virtual clock unless src.realtime); the figures of
// one source. Each step is found in the source's samples (the first one nearer the new rest
// point than the old), so a replay whose start is not known to the loop is measured the same way.
Result run(Source& src) {
  Result r;
  r.name = src.name;
  r.rate = src.rate;
  r.steps = src.path.steps;
  const Path& path = src.path;
  HandFilter filter;
  const int frames = static_cast<int>((path.duration() + (src.realtime ? 1.5 : 0)) * kFrameRate);
  std::vector<Vec3> overlay(frames, Vec3::Constant(NAN));
  std::vector<double> frame_t(frames);
  Vec3 shown = Vec3::Constant(NAN);
  double cpu = 0;
  const clockid_t clock = src.realtime ? CLOCK_PROCESS_CPUTIME_ID : CLOCK_THREAD_CPUTIME_ID;
  const double cpu_start = cpu_s(clock);
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < frames; ++k) {
    const double t = k / kFrameRate;
    frame_t[k] = t;
    if (src.realtime)
      std::this_thread::sleep_until(start + std::chrono::duration_cast<std::chrono::nanoseconds>(
                                                std::chrono::duration<double>(t)));
    src.deliver(t);
    const double c0 = cpu_s(clock);
    for (const HandFrame& raw : src.poll(t)) {
      const HandFrame f = filter.update(raw);
      if (f.tracked) shown = f.palm.position;
    }
    cpu += cpu_s(clock) - c0;
    overlay[k] = shown;
  }
  if (src.realtime) cpu = cpu_s(clock) - cpu_start;
  r.cpu_us_per_frame = 1e6 * cpu / frames;
  // The steps as the samples show them: step_t[s] the time of the first sample of rest s.
  std::vector<double> step_t(path.steps + 2, -1);
  step_t[0] = 0;
  step_t[path.steps + 1] = frame_t.back() + 1;
  for (size_t i = 0, s = 1; i < src.samples.size() && s <= static_cast<size_t>(path.steps); ++i) {
    const Vec3& p = src.samples[i];
    if (!p.allFinite()) continue;
    if ((p - path.at_rest(s)).norm() < (p - path.at_rest(s - 1)).norm())
      step_t[s++] = src.sample_times[i];
  }
  // Latency per step: from the frame of the first sample after the step.
  std::vector<double> onset, half;
  for (int s = 1; s <= path.steps; ++s) {
    if (step_t[s] < 0) continue;
    const Vec3 a = path.at_rest(s - 1), b = path.at_rest(s);
    const int k0 = static_cast<int>(std::ceil(step_t[s] * kFrameRate - 1e-9));
    const double until = step_t[s + 1] < 0 ? frame_t.back() + 1 : step_t[s + 1];
    int k_onset = -1, k_half = -1;
    for (int k = k0; k < frames && frame_t[k] < until; ++k) {
      if (!overlay[k].allFinite()) continue;
      const double covered = (overlay[k] - a).dot(b - a) / (b - a).squaredNorm();
      if (k_onset < 0 && covered >= kOnset) k_onset = k;
      if (k_half < 0 && covered >= kHalf) k_half = k;
    }
    if (k_onset < 0 || k_half < 0) continue;
    onset.push_back(k_onset - k0);
    half.push_back(k_half - k0);
    ++r.steps_seen;
  }
  r.onset_median = median(onset);
  r.half_median = median(half);
  r.onset_max = onset.empty() ? -1 : *std::max_element(onset.begin(), onset.end());
  r.half_max = half.empty() ? -1 : *std::max_element(half.begin(), half.end());
  // Jitter at rest: each rest from kSettle after its step to the next step.
  double raw2 = 0, filt2 = 0;
  int nraw = 0, nfilt = 0;
  for (int s = 0; s <= path.steps; ++s) {
    if (step_t[s] < 0 || step_t[s + 1] < 0) continue;
    const double from = step_t[s] + (s > 0 ? kSettle : 0), to = step_t[s + 1];
    std::vector<Vec3> raw, filt;
    for (size_t i = 0; i < src.samples.size(); ++i)
      if (src.sample_times[i] >= from && src.sample_times[i] < to && src.samples[i].allFinite())
        raw.push_back(src.samples[i]);
    for (int k = 0; k < frames; ++k)
      if (frame_t[k] >= from && frame_t[k] < to && overlay[k].allFinite())
        filt.push_back(overlay[k]);
    const double jr = rms_about_mean(raw), jf = rms_about_mean(filt);
    raw2 += jr * jr * static_cast<double>(raw.size());
    nraw += static_cast<int>(raw.size());
    filt2 += jf * jf * static_cast<double>(filt.size());
    nfilt += static_cast<int>(filt.size());
  }
  r.jitter_raw_mm = nraw ? 1e3 * std::sqrt(raw2 / nraw) : -1;
  r.jitter_filtered_mm = nfilt ? 1e3 * std::sqrt(filt2 / nfilt) : -1;
  return r;
}

// Noisy palm samples at `rate` along the path.
void noisy_samples(double rate, uint32_t seed, std::vector<double>& times, std::vector<Vec3>& pos) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, 0.002);
  for (int i = 0; i / rate < kPath.duration(); ++i) {
    const double t = i / rate;
    times.push_back(t);
    pos.push_back(kPath.truth(t) + Vec3(noise(rng), noise(rng), noise(rng)));
  }
}

// The UDP stream: packets sent on loopback as their samples fall due, received by
// UdpSkeletonSource (frames stamped with the frame's time, as the app's receive time is).
struct UdpBench {
  UdpSkeletonSource source{0};
  int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  size_t next = 0;
  uint32_t seq = 1;
  ~UdpBench() {
    if (fd >= 0) ::close(fd);
  }
};

// A Kinect depth frame (640x480 raw 11-bit): a wall at 2.6 m, a torso at 1.6 m and the palm, a
// disc of 8 cm radius at its depth, with per-pixel noise (as tests/tracking/kinect_test.cpp's
// scenes). The sensor's frame-to-frame noise of a hand's outline and depth is modelled by moving
// the disc by a random 1 px (s.d.) across the image and 2 mm in depth in each frame.
std::vector<uint16_t> depth_frame(const Vec3& palm, std::mt19937& rng) {
  const DepthIntrinsics k;
  std::normal_distribution<double> noise(0, 0.0025), outline(0, 1.0), depth(0, 0.002);
  const double z = -palm.z() + depth(rng);
  const double hu = k.cx + palm.x() * k.fx / z + outline(rng);
  const double hv = k.cy - palm.y() * k.fy / z + outline(rng);
  const double r = 0.08 * k.fx / z;
  std::vector<uint16_t> f(640 * 480);
  for (int v = 0; v < 480; ++v)
    for (int u = 0; u < 640; ++u) {
      double d = 2.6;
      if (u > 300 && u < 500 && v > 150) d = 1.6;
      if (std::hypot(u - hu, v - hv) < r) d = z;
      f[v * 640 + u] = kinect_m_to_raw(d + noise(rng));
    }
  return f;
}

nlohmann::json to_json(const Result& r) {
  return {{"source", r.name},
          {"rate_hz", r.rate},
          {"steps_seen", r.steps_seen},
          {"steps", r.steps},
          {"onset_frames_median", r.onset_median},
          {"onset_frames_max", r.onset_max},
          {"half_frames_median", r.half_median},
          {"half_frames_max", r.half_max},
          {"jitter_raw_mm", r.jitter_raw_mm},
          {"jitter_filtered_mm", r.jitter_filtered_mm},
          {"cpu_us_per_frame", r.cpu_us_per_frame}};
}

Result from_json(const nlohmann::json& j) {
  Result r;
  r.name = j.at("source").get<std::string>();
  r.rate = j.at("rate_hz").get<double>();
  r.steps_seen = j.at("steps_seen").get<int>();
  r.steps = j.at("steps").get<int>();
  r.onset_median = j.at("onset_frames_median").get<double>();
  r.onset_max = j.at("onset_frames_max").get<double>();
  r.half_median = j.at("half_frames_median").get<double>();
  r.half_max = j.at("half_frames_max").get<double>();
  r.jitter_raw_mm = j.at("jitter_raw_mm").get<double>();
  r.jitter_filtered_mm = j.at("jitter_filtered_mm").get<double>();
  r.cpu_us_per_frame = j.at("cpu_us_per_frame").get<double>();
  return r;
}

// Writes the replay path as a fakenect recording (as tests/tracking/kinect_test.cpp does): DIR/
// INDEX.txt and one d-<time>-<timestamp>.pgm per depth frame (a one-line PGM header, then the
// 640x480 raw 11-bit values).
bool write_recording(const std::string& dir, std::string& why) {
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    why = dir + ": " + ec.message();
    return false;
  }
  std::ofstream index(dir + "/INDEX.txt");
  std::mt19937 rng(17);
  for (int i = 0; i / 30.0 < kReplayPath.duration(); ++i) {
    char name[64];
    std::snprintf(name, sizeof name, "d-%.6f-%u.pgm", 1000.0 + i / 30.0, 1000u + 100u * i);
    const std::vector<uint16_t> raw = depth_frame(kReplayPath.truth(i / 30.0), rng);
    std::ofstream out(dir + "/" + name, std::ios::binary);
    out << "P5 640 480 65535\n";
    out.write(reinterpret_cast<const char*>(raw.data()),
              static_cast<std::streamsize>(raw.size() * sizeof(uint16_t)));
    index << name << "\n";
    if (!out) {
      why = dir + "/" + name + ": cannot write";
      return false;
    }
  }
  return static_cast<bool>(index) || (why = dir + "/INDEX.txt: cannot write", false);
}

// Runs the replay child under fakenect; its Result, or none (with why).
std::optional<Result> kinect_replay(const std::string& work_dir, std::string& why) {
  char self[4096];
  const ssize_t n = ::readlink("/proc/self/exe", self, sizeof self - 1);
  if (n <= 0) {
    why = "cannot find this executable (/proc/self/exe)";
    return std::nullopt;
  }
  self[n] = 0;
  const std::string dir = work_dir + "/fakenect_rec";
  if (!write_recording(dir, why)) return std::nullopt;
  const std::string cmd =
      "FAKENECT_LOOP=0 fakenect '" + dir + "' '" + self + "' --kinect-replay '" + dir + "' 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) {
    why = "cannot run fakenect";
    return std::nullopt;
  }
  std::string all, result;
  char line[4096];
  while (std::fgets(line, sizeof line, p)) {
    all += line;
    if (std::string(line).rfind("kinect-replay ", 0) == 0) result = line + 14;
  }
  const int rc = ::pclose(p);
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  if (rc != 0 || result.empty()) {
    why = "the replay failed (exit " + std::to_string(rc) + "): " + all;
    return std::nullopt;
  }
  return from_json(nlohmann::json::parse(result));
}

}  // namespace

int run_kinect_replay_child(const std::string& dir) {
  KinectSource kinect({}, 0, dir);
  Source s;
  s.name = "kinect (fakenect replay)";
  s.rate = 30;
  s.path = kReplayPath;
  s.realtime = true;
  s.deliver = [](double) {};
  s.poll = [&kinect, &s](double t) {
    std::vector<HandFrame> frames = kinect.poll();
    for (const HandFrame& f : frames) {
      s.sample_times.push_back(t);
      s.samples.push_back(f.palm.position);
    }
    return frames;
  };
  const Result r = run(s);
  if (s.samples.empty()) {
    std::printf("kinect-replay-error no palm from the replay: %s\n",
                kinect.status().message.c_str());
    return 1;
  }
  std::printf("kinect-replay %s\n", to_json(r).dump().c_str());
  return 0;
}

nlohmann::json run_source_benchmarks(const std::string& work_dir, const std::string& csv_path) {
  std::vector<Result> results;

  {  // UDP stream, 60 Hz
    Source s;
    s.name = "udp (60 Hz)";
    s.rate = 60;
    noisy_samples(s.rate, 11, s.sample_times, s.samples);
    auto u = std::make_shared<UdpBench>();
    u->to.sin_family = AF_INET;
    u->to.sin_port = htons(u->source.port());
    ::inet_pton(AF_INET, "127.0.0.1", &u->to.sin_addr);
    s.deliver = [u, &s](double t) {
      while (u->next < s.sample_times.size() && s.sample_times[u->next] <= t + 1e-9) {
        const auto b = encode_udp_packet(u->seq++, s.sample_times[u->next],
                                         {palm_frame(s.sample_times[u->next], s.samples[u->next])});
        ::sendto(u->fd, b.data(), b.size(), 0, reinterpret_cast<const sockaddr*>(&u->to),
                 sizeof u->to);
        ++u->next;
      }
    };
    s.poll = [u](double t) {
      auto frames = u->source.poll();
      for (auto& f : frames) f.time = t;
      return frames;
    };
    results.push_back(run(s));
    if (u->source.stats().dropped() > 0)
      std::printf("udp: %s\n", u->source.status().message.c_str());
  }

  {  // Kinect depth frames, 30 Hz, segmented as KinectSource's thread does
    Source s;
    s.name = "kinect (30 Hz depth)";
    s.rate = 30;
    std::mt19937 rng(5);
    std::vector<std::vector<uint16_t>> depth;
    for (int i = 0; i / s.rate < kPath.duration(); ++i) {
      s.sample_times.push_back(i / s.rate);
      depth.push_back(depth_frame(kPath.truth(i / s.rate), rng));
    }
    auto seg = std::make_shared<HandSegmenter>();
    auto next = std::make_shared<size_t>(0);
    auto pending = std::make_shared<std::vector<size_t>>();
    s.deliver = [next, pending, &s](double t) {
      while (*next < s.sample_times.size() && s.sample_times[*next] <= t + 1e-9)
        pending->push_back((*next)++);
    };
    s.samples.assign(s.sample_times.size(), Vec3::Constant(NAN));
    s.poll = [seg, pending, &depth, &s](double) {
      std::vector<HandFrame> out;
      for (size_t i : *pending)
        for (const HandFrame& f :
             seg->process_raw11(depth[i].data(), 640, 480, s.sample_times[i])) {
          s.samples[i] = f.palm.position;
          out.push_back(f);
        }
      pending->clear();
      return out;
    };
    results.push_back(run(s));
    // Depth frames in which the segmenter found no palm (left out of the raw jitter).
    const auto found = std::count_if(s.samples.begin(), s.samples.end(),
                                     [](const Vec3& p) { return p.allFinite(); });
    if (found != static_cast<long>(s.samples.size()))
      std::printf("kinect: the palm found in %ld of %zu depth frames\n", static_cast<long>(found),
                  s.samples.size());
  }

  {  // The same depth frames as a fakenect recording, through libfreenect in real time
    std::string why;
    if (auto r = kinect_replay(work_dir, why))
      results.push_back(*r);
    else
      std::printf("kinect (fakenect replay): not measured: %s\n", why.c_str());
  }

  {  // A trace file, 60 Hz
    Source s;
    s.name = "trace file (60 Hz)";
    s.rate = 60;
    noisy_samples(s.rate, 13, s.sample_times, s.samples);
    const std::string path = work_dir + "/tracking_sources_trace.csv";
    {
      TraceRecorder rec(path);
      for (size_t i = 0; i < s.samples.size(); ++i)
        rec.write(palm_frame(s.sample_times[i], s.samples[i]));
    }
    auto trace = std::make_shared<TraceSource>(path);
    s.deliver = [](double) {};  // the file is the source: nothing to send
    s.poll = [trace](double t) {
      trace->set_time(t);
      return trace->poll();
    };
    results.push_back(run(s));
    if (trace->status().state == SourceState::Error)
      std::printf("trace: %s\n", trace->status().message.c_str());
  }

  std::printf(
      "\nHand sources in the app's frame loop (virtual 90 Hz; %d steps of %.0f cm, rests of %.0f "
      "s)\n",
      kPath.steps, kStepM * 100, kPath.rest);
  std::printf("%-26s %16s %16s %12s %12s %14s\n", "source", "onset (frames)", "50 % (frames)",
              "jitter raw", "filtered", "CPU/frame");
  std::printf("%-26s %16s %16s %12s %12s %14s\n", "", "median / max", "median / max", "(mm RMS)",
              "(mm RMS)", "(us)");
  nlohmann::json j = nlohmann::json::array();
  std::ofstream csv(csv_path);
  csv << "source,rate_hz,steps_seen,onset_frames_median,onset_frames_max,half_frames_median,"
         "half_frames_max,jitter_raw_mm,jitter_filtered_mm,cpu_us_per_frame\n";
  for (const Result& r : results) {
    std::printf("%-26s %9.0f / %-4.0f %9.0f / %-4.0f %12.2f %12.2f %14.1f\n", r.name.c_str(),
                r.onset_median, r.onset_max, r.half_median, r.half_max, r.jitter_raw_mm,
                r.jitter_filtered_mm, r.cpu_us_per_frame);
    csv << '"' << r.name << '"' << ',' << r.rate << ',' << r.steps_seen << ',' << r.onset_median
        << ',' << r.onset_max << ',' << r.half_median << ',' << r.half_max << ',' << r.jitter_raw_mm
        << ',' << r.jitter_filtered_mm << ',' << r.cpu_us_per_frame << '\n';
    j.push_back(to_json(r));
  }
  std::printf(
      "onset / 50 %%: frames from the first sample after the step to the overlay covering 10 / 50 "
      "%% of it (the app's pose-to-photon adds 0 frames). The fakenect replay runs in real time "
      "(%d steps, rests of %.0f s; CPU: the whole process, libfreenect's thread included); wrote "
      "%s\n",
      kReplayPath.steps, kReplayPath.rest, csv_path.c_str());
  return j;
}

}  // namespace drape::bench
