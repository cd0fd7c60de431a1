#include "tracking/trace.hpp"

#include <gtest/gtest.h>

#include <fstream>

using namespace drape::tracking;

TEST(Trace, RecordAndReplay) {
  const std::string path = std::string(DRAPE_BINARY_DIR) + "/trace_test.csv";
  std::vector<HandFrame> in;
  {
    TraceRecorder rec(path);
    ASSERT_TRUE(rec.ok());
    for (int i = 0; i < 20; ++i) {
      HandFrame f;
      f.time = 100.0 + i / 30.0;
      f.hand = i % 2 ? Hand::Left : Hand::Right;
      f.tracked = i != 7;
      f.confidence = 0.5 + i * 0.01;
      f.palm.position = Vec3(0.01 * i, 1.0, -0.5 + 1e-7 * i);
      f.has_joints = i % 3 == 0;
      for (int j = 0; j < kJointCount; ++j) f.joints[j] = Vec3(j, i, 0.123456789);
      rec.write(f);
      in.push_back(f);
    }
  }
  TraceSource src(path);
  ASSERT_EQ(src.status().state, SourceState::Ok) << src.status().message;
  src.set_time(0.2);  // 0.2 s -> frames 0..6
  auto a = src.poll();
  EXPECT_EQ(a.size(), 7u);
  src.set_time(10);
  auto b = src.poll();
  EXPECT_EQ(a.size() + b.size(), in.size());
  EXPECT_TRUE(src.finished());
  a.insert(a.end(), b.begin(), b.end());
  for (size_t i = 0; i < in.size(); ++i) {
    EXPECT_NEAR(a[i].time, in[i].time, 1e-9);
    EXPECT_EQ(a[i].hand, in[i].hand);
    EXPECT_EQ(a[i].tracked, in[i].tracked);
    EXPECT_NEAR((a[i].palm.position - in[i].palm.position).norm(), 0, 1e-9);
    EXPECT_EQ(a[i].has_joints, in[i].has_joints);
    if (in[i].has_joints) {
      EXPECT_NEAR((a[i].joints[25] - in[i].joints[25]).norm(), 0, 1e-8);
    }
  }
}

TEST(Trace, BadFilesNameFileAndLine) {
  const std::string path = std::string(DRAPE_BINARY_DIR) + "/trace_bad.csv";
  std::string err;
  std::ofstream(path) << "time,hand\n";
  EXPECT_FALSE(read_trace(path, &err));
  EXPECT_NE(err.find("header"), std::string::npos);
  std::ofstream(path) << "# drape-trace v1\n0,0,1,1,0,0,0,0,0,0,1,0\n0.1,0,1,1,abc,0,0,0,0,0,1,0\n";
  EXPECT_FALSE(read_trace(path, &err));
  EXPECT_NE(err.find(":3:"), std::string::npos) << err;
  std::ofstream(path) << "# drape-trace v1\n0,0,1,1,0,0,0,0,0,0,1\n";
  EXPECT_FALSE(read_trace(path, &err));
  std::ofstream(path) << "# drape-trace v1\n1,0,1,1,0,0,0,0,0,0,1,0\n0.5,0,1,1,0,0,0,0,0,0,1,0\n";
  EXPECT_FALSE(read_trace(path, &err));
  EXPECT_NE(err.find("backwards"), std::string::npos);
  TraceSource missing(path + ".nope");
  EXPECT_EQ(missing.status().state, SourceState::Error);
  EXPECT_TRUE(missing.poll().empty());
}
