#include "tracking/kinect.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <opencv2/core.hpp>
#include <random>
#include <sstream>

using namespace drape::tracking;

namespace {
// Synthetic scene in millimetres: wall at 2.6 m, torso at 1.6 m, hands as discs at 1.1 m
// (8 cm radius), a little noise and dropouts.
cv::Mat scene(const std::vector<std::array<double, 3>>& hands, unsigned seed) {
  cv::Mat d(480, 640, CV_16UC1, cv::Scalar(2600));
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0, 3);
  DepthIntrinsics k;
  for (int v = 0; v < 480; ++v)
    for (int u = 0; u < 640; ++u) {
      double z = 2.6;
      if (u > 220 && u < 420 && v > 150) z = 1.6;  // torso
      for (const auto& h : hands) {
        const double r_px = 0.08 * k.fx / h[2];
        if (std::hypot(u - h[0], v - h[1]) < r_px) z = h[2];
      }
      d.at<uint16_t>(v, u) = static_cast<uint16_t>(z * 1000 + n(rng));
      if ((u * 7 + v * 13) % 97 == 0) d.at<uint16_t>(v, u) = 0;  // dropouts
    }
  return d;
}
}  // namespace

TEST(Kinect, RawDisparityConversionRoundTrips) {
  for (double m : {0.6, 1.0, 1.5, 2.5, 3.5}) {
    const double back = kinect_raw_to_m(kinect_m_to_raw(m));
    EXPECT_NEAR(back, m, 0.02 * m * m) << m;  // quantisation grows with depth^2
  }
  EXPECT_EQ(kinect_raw_to_m(2047), 0.0);
}

TEST(Kinect, SegmentsTwoHandsOnSyntheticDepth) {
  HandSegmenter seg;
  const std::vector<std::array<double, 3>> truth = {{200, 200, 1.1}, {450, 230, 1.15}};
  auto hands = seg.detect(scene(truth, 1));
  ASSERT_EQ(hands.size(), 2u);
  DepthIntrinsics k;
  for (size_t i = 0; i < 2; ++i) {
    const Vec3 expect = k.unproject(truth[i][0], truth[i][1], truth[i][2]);
    const double err = (hands[i].position - expect).norm();
    std::printf("hand %zu: pixel (%.1f, %.1f) vs (%.0f, %.0f), 3D error %.4f m\n", i, hands[i].u,
                hands[i].v, truth[i][0], truth[i][1], err);
    EXPECT_LT(err, 0.01);
  }
  // Nothing near: only the torso band -> one blob, which is large; no hands in an empty room.
  auto none = seg.detect(cv::Mat(480, 640, CV_16UC1, cv::Scalar(0)));
  EXPECT_TRUE(none.empty());
}

TEST(Kinect, Raw11PathAssignsHandsMirrored) {
  HandSegmenter seg;
  const std::vector<std::array<double, 3>> truth = {{200, 200, 1.1}, {450, 230, 1.1}};
  cv::Mat mm = scene(truth, 2);
  std::vector<uint16_t> raw(640 * 480);
  for (int i = 0; i < 640 * 480; ++i) {
    const uint16_t z = mm.ptr<uint16_t>()[i];
    raw[i] = z ? kinect_m_to_raw(z / 1000.0) : 2047;
  }
  auto frames = seg.process_raw11(raw.data(), 640, 480, 1.0);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].hand, Hand::Right);  // image left = user's right
  EXPECT_EQ(frames[1].hand, Hand::Left);
  EXPECT_LT(frames[0].palm.position.x(), frames[1].palm.position.x());
  EXPECT_NEAR(frames[0].palm.position.z(), -1.1, 0.02);
}

namespace {
// Writes a fakenect recording of 4 frames of one hand at `truth` (INDEX.txt +
// d-<time>-<timestamp>.pgm, 11-bit raw after a one-line PGM header) and runs the probe on it
// under fakenect (FAKENECT_LOOP=0) until `frames` frames or the stream's end. Returns the probe's
// output and sets *rc to its exit status.
std::string probe_recording(const std::string& dir, const std::array<double, 3>& truth, int frames,
                            int* rc) {
  ::mkdir(dir.c_str(), 0755);
  std::ofstream index(dir + "/INDEX.txt");
  for (int f = 0; f < 4; ++f) {
    cv::Mat mm = scene({truth}, 10 + f);
    char name[64];
    std::snprintf(name, sizeof name, "d-%.6f-%u.pgm", 1000.0 + f / 30.0, 1000u + 100u * f);
    std::ofstream out(dir + "/" + name, std::ios::binary);
    out << "P5 640 480 65535\n";
    std::vector<uint16_t> raw(640 * 480);
    for (int i = 0; i < 640 * 480; ++i) {
      const uint16_t z = mm.ptr<uint16_t>()[i];
      raw[i] = z ? kinect_m_to_raw(z / 1000.0) : 2047;
    }
    out.write(reinterpret_cast<const char*>(raw.data()), raw.size() * 2);
    index << name << "\n";
  }
  index.close();
  const std::string cmd = "FAKENECT_LOOP=0 fakenect " + dir + " " + DRAPE_BINARY_DIR +
                          "/bin/tracking_kinect_probe " + std::to_string(frames) + " 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  std::string all;
  if (!p) {
    *rc = -1;
    return all;
  }
  char line[512];
  while (std::fgets(line, sizeof line, p)) all += line;
  *rc = ::pclose(p);
  std::printf("%s", all.c_str());
  return all;
}
}  // namespace

// The real libfreenect code path through fakenect's library.
TEST(Kinect, ReplaysThroughFakenect) {
  int rc = 0;
  const std::string all =
      probe_recording(std::string(DRAPE_BINARY_DIR) + "/fakenect_rec", {300, 220, 1.0}, 3, &rc);
  ASSERT_EQ(rc, 0) << all;
  std::vector<Vec3> palms;
  std::istringstream lines(all);
  for (std::string line; std::getline(lines, line);) {
    char hand[16];
    double x, y, z;
    if (std::sscanf(line.c_str(), "%15s %lf %lf %lf", hand, &x, &y, &z) == 4)
      palms.emplace_back(x, y, z);
  }
  ASSERT_GE(palms.size(), 3u) << all;
  const Vec3 expect = DepthIntrinsics{}.unproject(300, 220, 1.0);
  for (const auto& q : palms) EXPECT_LT((q - expect).norm(), 0.015) << q.transpose();
}

// The recording's end (FAKENECT_LOOP=0) is the stream's end: an Error status naming the
// recording, the source no longer running.
TEST(Kinect, RecordingEndIsAStatusNamingIt) {
  const std::string dir = std::string(DRAPE_BINARY_DIR) + "/fakenect_rec_end";
  int rc = 0;
  const std::string all = probe_recording(dir, {300, 220, 1.0}, 100, &rc);
  ASSERT_EQ(rc, 0) << all;
  EXPECT_NE(all.find("frames 4\n"), std::string::npos) << all;
  EXPECT_NE(all.find("status kinect: the recording " + dir + " ended"), std::string::npos) << all;
}

TEST(Kinect, MissingRecordingGivesStatusNotExit) {
  KinectSource k({}, 0, "/nonexistent/rec");
  EXPECT_EQ(k.status().state, SourceState::Unavailable);
  EXPECT_NE(k.status().message.find("INDEX.txt"), std::string::npos);
  EXPECT_TRUE(k.poll().empty());
}
