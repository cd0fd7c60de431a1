// The hand sources as the app runs them (bench/tracking_sources.cpp, part of tracking_bench):
// for the UDP stream, a Kinect depth stream and a trace file, the latency from a step of the
// palm at the source to the first frame whose hand overlay shows it, the jitter at rest before
// and after the One-Euro filter, and the CPU time per frame.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace drape::bench {

// Runs the three sources on the same palm path (rests and 10 cm steps) in a 90 Hz frame loop,
// prints the table, writes `csv_path` and returns the figures as JSON. `work_dir` holds the
// trace file it writes.
// A fakenect recording of the same path is replayed through libfreenect in a child process
// (`fakenect DIR <this executable> --kinect-replay DIR`, in real time).
nlohmann::json run_source_benchmarks(const std::string& work_dir, const std::string& csv_path);

// The child of that replay: KinectSource on the recording DIR in a real-time 90 Hz loop; prints
// one line "kinect-replay {figures as JSON}" (or "kinect-replay-error MESSAGE" and returns 1).
int run_kinect_replay_child(const std::string& dir);

}  // namespace drape::bench
