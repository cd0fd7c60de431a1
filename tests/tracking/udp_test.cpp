#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>

#include "tests/tracking/udp_test_sender.hpp"
#include "tracking/udp_source.hpp"

using namespace drape::tracking;

namespace {
HandFrame sample_hand(Hand h, bool joints) {
  HandFrame f;
  f.hand = h;
  f.tracked = true;
  f.confidence = 0.75;
  f.has_joints = joints;
  f.palm.position = Vec3(0.1, 1.2, -0.4);
  f.palm.orientation = Quat(Eigen::AngleAxisd(0.4, Vec3::UnitZ()));
  for (int j = 0; j < kJointCount; ++j) f.joints[j] = Vec3(0.1 + 0.01 * j, 1.2, -0.4);
  return f;
}
}  // namespace

TEST(UdpPacket, RoundTrip) {
  auto b =
      encode_udp_packet(42, 12.5, {sample_hand(Hand::Left, true), sample_hand(Hand::Right, false)});
  EXPECT_EQ(b.size(), kUdpHeaderSize + (24 + 12 * 26) + (24 + 12));
  UdpPacket p;
  std::string why;
  ASSERT_TRUE(parse_udp_packet(b.data(), b.size(), p, &why)) << why;
  EXPECT_EQ(p.sequence, 42u);
  EXPECT_DOUBLE_EQ(p.timestamp, 12.5);
  ASSERT_EQ(p.hands.size(), 2u);
  EXPECT_TRUE(p.hands[0].has_joints);
  EXPECT_NEAR(p.hands[0].joints[25].x(), 0.1 + 0.25, 1e-6);
  EXPECT_FALSE(p.hands[1].has_joints);
  EXPECT_NEAR((p.hands[1].palm.position - Vec3(0.1, 1.2, -0.4)).norm(), 0, 1e-6);
  EXPECT_NEAR(p.hands[1].confidence, 0.75, 1e-6);
  EXPECT_NEAR(
      p.hands[1].palm.orientation.angularDistance(sample_hand(Hand::Right, false).palm.orientation),
      0, 1e-5);
}

TEST(UdpPacket, RejectsTruncatedOversizedNaNAndGarbage) {
  auto good = encode_udp_packet(1, 0.0, {sample_hand(Hand::Left, true)});
  UdpPacket p;
  std::string why;
  for (size_t n = 0; n < good.size(); ++n) EXPECT_FALSE(parse_udp_packet(good.data(), n, p, &why));
  std::vector<uint8_t> big(good);
  big.resize(kUdpMaxPacket + 1);
  EXPECT_FALSE(parse_udp_packet(big.data(), big.size(), p, &why));
  EXPECT_NE(why.find("oversized"), std::string::npos);
  auto extra = good;
  extra.push_back(0);
  EXPECT_FALSE(parse_udp_packet(extra.data(), extra.size(), p, &why));
  auto nan = good;
  const float q = std::nanf("");
  std::memcpy(nan.data() + kUdpHeaderSize + 24 + 12 * 3 + 4, &q, 4);
  EXPECT_FALSE(parse_udp_packet(nan.data(), nan.size(), p, &why));
  EXPECT_NE(why.find("not finite"), std::string::npos) << why;
  auto far = good;
  const float k = 1e6f;
  std::memcpy(far.data() + kUdpHeaderSize + 24, &k, 4);
  EXPECT_FALSE(parse_udp_packet(far.data(), far.size(), p, &why));
  auto magic = good;
  magic[0] ^= 0xff;
  EXPECT_FALSE(parse_udp_packet(magic.data(), magic.size(), p, &why));
  auto ver = good;
  ver[4] = 9;
  EXPECT_FALSE(parse_udp_packet(ver.data(), ver.size(), p, &why));
  auto joints = good;
  joints[kUdpHeaderSize + 2] = 5;
  EXPECT_FALSE(parse_udp_packet(joints.data(), joints.size(), p, &why));
  auto two =
      encode_udp_packet(1, 0.0, {sample_hand(Hand::Left, false), sample_hand(Hand::Left, false)});
  EXPECT_FALSE(parse_udp_packet(two.data(), two.size(), p, &why));
  EXPECT_NE(why.find("duplicate"), std::string::npos);
}

TEST(UdpSource, LoopbackCountsMalformedAndStale) {
  UdpSkeletonSource src(0);  // 127.0.0.1, free port
  ASSERT_NE(src.status().state, SourceState::Unavailable) << src.status().message;
  ASSERT_GT(src.port(), 0);
  const test_support::LoopbackSender sender(src.port());
  auto send = [&](const std::vector<uint8_t>& b) { sender.send(b); };
  send(encode_udp_packet(10, 1.0, {sample_hand(Hand::Right, true)}));
  auto trunc = encode_udp_packet(11, 1.0, {sample_hand(Hand::Right, true)});
  trunc.resize(30);
  send(trunc);
  send(std::vector<uint8_t>(1500, 0xab));                              // oversized garbage
  send(encode_udp_packet(9, 0.9, {sample_hand(Hand::Right, false)}));  // stale
  send(encode_udp_packet(12, 1.1, {sample_hand(Hand::Left, false)}));
  std::vector<HandFrame> got;
  for (int i = 0; i < 100 && got.size() < 2; ++i) {
    for (auto& f : src.poll()) got.push_back(f);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].hand, Hand::Right);
  EXPECT_EQ(got[1].hand, Hand::Left);
  EXPECT_EQ(src.stats().accepted, 2u);
  EXPECT_EQ(src.stats().malformed, 2u);
  EXPECT_EQ(src.stats().stale, 1u);
  std::printf("%s\n", src.status().message.c_str());
}

TEST(UdpSource, BadAddressGivesStatus) {
  UdpSkeletonSource src(0, "not-an-address");
  EXPECT_EQ(src.status().state, SourceState::Unavailable);
  EXPECT_TRUE(src.poll().empty());
}

TEST(UdpSource, DropsOldTimestampsAndHugeDatagrams) {
  UdpSkeletonSource src(0);
  ASSERT_NE(src.status().state, SourceState::Unavailable) << src.status().message;
  const test_support::LoopbackSender sender(src.port());
  auto send = [&](const std::vector<uint8_t>& b) { sender.send(b); };
  send(encode_udp_packet(1, 5.0, {sample_hand(Hand::Right, false)}));
  send(encode_udp_packet(2, 4.0, {sample_hand(Hand::Right, false)}));  // a new number, old time
  send(std::vector<uint8_t>(9000, 0x44));                              // beyond the read buffer
  send(encode_udp_packet(3, 5.0, {sample_hand(Hand::Right, false)}));  // the same time: kept
  std::vector<HandFrame> got;
  for (int i = 0; i < 100 && src.stats().received < 4; ++i) {
    for (auto& f : src.poll()) got.push_back(f);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_EQ(got.size(), 2u);
  EXPECT_EQ(src.stats().stale, 1u);
  EXPECT_EQ(src.stats().malformed, 1u);
  EXPECT_NE(src.stats().last_error.find("oversized packet (9000 bytes)"), std::string::npos)
      << src.stats().last_error;
}
