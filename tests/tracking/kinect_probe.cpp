// Runs KinectSource until `frames` depth frames were processed and prints the detected palms
// ("hand x y z" per line, then "frames N" and "status ..."). Used under fakenect by
// kinect_test; exits 2 when the source is unavailable.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include "tracking/kinect.hpp"

int main(int argc, char** argv) {
  using namespace drape::tracking;
  const unsigned frames = argc > 1 ? static_cast<unsigned>(std::atoi(argv[1])) : 3;
  const char* recording = std::getenv("FAKENECT_PATH");  // set by the fakenect wrapper
  KinectSource k({}, 0, recording ? recording : "");
  const auto t0 = std::chrono::steady_clock::now();
  unsigned printed = 0;
  while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(20)) {
    for (const auto& f : k.poll()) {
      std::printf("%s %.5f %.5f %.5f\n", hand_name(f.hand), f.palm.position.x(),
                  f.palm.position.y(), f.palm.position.z());
      ++printed;
    }
    if (k.frames_processed() >= frames || (!k.running() && k.status().state != SourceState::Ok))
      break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  for (const auto& f : k.poll())
    std::printf("%s %.5f %.5f %.5f\n", hand_name(f.hand), f.palm.position.x(), f.palm.position.y(),
                f.palm.position.z());
  std::printf("frames %llu\nstatus %s\n", static_cast<unsigned long long>(k.frames_processed()),
              k.status().message.c_str());
  return k.frames_processed() > 0 ? 0 : 2;
}
