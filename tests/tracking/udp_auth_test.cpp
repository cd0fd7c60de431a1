// Signed UDP packets (tracking/udp_auth.cpp): forged, truncated, replayed and wrong-key packets
// are refused; the key file's format and permissions; a keyed source over loopback.
#include "tracking/udp_auth.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "tests/tracking/udp_test_sender.hpp"

using namespace drape::tracking;

namespace {
UdpKey key_of(uint8_t seed) {
  UdpKey k{};
  for (size_t i = 0; i < k.size(); ++i) k[i] = static_cast<uint8_t>(seed + 7 * i);
  return k;
}

HandFrame palm(Hand h, double x) {
  HandFrame f;
  f.hand = h;
  f.tracked = true;
  f.confidence = 0.9;
  f.palm.position = Vec3(x, 1.2, 0.1);
  return f;
}

std::string temp_dir(const std::string& name) {
  const auto d = std::filesystem::path(DRAPE_BINARY_DIR) / "test_out" / name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d.string();
}
}  // namespace

TEST(UdpAuth, SignedRoundTrip) {
  const UdpKey k = key_of(1);
  auto b = encode_signed_udp_packet(5, 2.5, {palm(Hand::Right, 0.3)}, k);
  EXPECT_EQ(b.size(), kUdpHeaderSize + 24 + 12 + kUdpTagSize);
  UdpPacket p;
  std::string why;
  ASSERT_EQ(verify_signed_udp_packet(b.data(), b.size(), k, p, &why), UdpAuth::Ok) << why;
  EXPECT_EQ(p.sequence, 5u);
  EXPECT_DOUBLE_EQ(p.timestamp, 2.5);
  ASSERT_EQ(p.hands.size(), 1u);
  EXPECT_NEAR(p.hands[0].palm.position.x(), 0.3, 1e-6);
}

TEST(UdpAuth, ForgedWrongKeyUnsignedAndTruncatedAreRefused) {
  const UdpKey k = key_of(1);
  const auto good = encode_signed_udp_packet(5, 2.5, {palm(Hand::Right, 0.3)}, k);
  UdpPacket p;
  std::string why;
  // Every single flipped bit of header, payload or tag: forged (or, for the magic, malformed).
  for (size_t i = 0; i < good.size(); ++i) {
    auto f = good;
    f[i] ^= 0x10;
    const UdpAuth a = verify_signed_udp_packet(f.data(), f.size(), k, p, &why);
    EXPECT_NE(a, UdpAuth::Ok) << "byte " << i;
    if (i >= 8) {
      EXPECT_EQ(a, UdpAuth::Forged) << "byte " << i << ": " << why;
    }
  }
  // Another key.
  EXPECT_EQ(verify_signed_udp_packet(good.data(), good.size(), key_of(2), p, &why),
            UdpAuth::Forged);
  EXPECT_NE(why.find("bad signature"), std::string::npos) << why;
  // An unsigned packet, and one relabelled as signed without a tag.
  auto plain = encode_udp_packet(5, 2.5, {palm(Hand::Right, 0.3)});
  EXPECT_EQ(verify_signed_udp_packet(plain.data(), plain.size(), k, p, &why), UdpAuth::Forged);
  EXPECT_NE(why.find("unsigned"), std::string::npos) << why;
  plain[4] = 2;
  EXPECT_EQ(verify_signed_udp_packet(plain.data(), plain.size(), k, p, &why), UdpAuth::Forged);
  // Truncated anywhere: never accepted.
  for (size_t n = 0; n < good.size(); ++n)
    EXPECT_NE(verify_signed_udp_packet(good.data(), n, k, p, &why), UdpAuth::Ok) << n;
  // A tag that is right for a body that does not parse: malformed, not accepted.
  std::vector<uint8_t> junk(good.begin(), good.end() - kUdpTagSize);
  junk[20] = 3;  // hand_count 3
  const auto tag = udp_tag(junk.data(), junk.size(), k);
  junk.insert(junk.end(), tag.begin(), tag.end());
  EXPECT_EQ(verify_signed_udp_packet(junk.data(), junk.size(), k, p, &why), UdpAuth::Malformed);
  // The unsigned parser refuses a signed packet and says why.
  EXPECT_FALSE(parse_udp_packet(good.data(), good.size(), p, &why));
  EXPECT_NE(why.find("pairing key"), std::string::npos) << why;
}

TEST(UdpAuth, KnownTag) {
  // RFC 4231 test case 2: key "Jefe", data "what do ya want for nothing?" (the key padded with
  // zeros to 32 bytes gives the same HMAC, as HMAC pads keys to the block size).
  UdpKey k{};
  std::memcpy(k.data(), "Jefe", 4);
  const std::string msg = "what do ya want for nothing?";
  const auto tag = udp_tag(reinterpret_cast<const uint8_t*>(msg.data()), msg.size(), k);
  UdpKey t{};
  std::copy(tag.begin(), tag.end(), t.begin());
  EXPECT_EQ(udp_key_hex(t), "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843");
}

TEST(UdpAuth, KeyHexAndFile) {
  const UdpKey k = key_of(9);
  const std::string hex = udp_key_hex(k);
  EXPECT_EQ(hex.size(), 64u);
  std::string why;
  auto back = parse_udp_key_hex("  " + hex + "\n", &why);
  ASSERT_TRUE(back) << why;
  EXPECT_EQ(*back, k);
  EXPECT_FALSE(parse_udp_key_hex(hex.substr(2), &why));
  EXPECT_NE(why.find("64 hex digits"), std::string::npos) << why;
  std::string bad = hex;
  bad[10] = 'g';
  EXPECT_FALSE(parse_udp_key_hex(bad, &why));
  EXPECT_NE(why.find("hex digit"), std::string::npos) << why;

  const std::string dir = temp_dir("udp_auth_key");
  const std::string path = dir + "/sub/hands.key";
  ASSERT_TRUE(save_udp_key(path, k, &why)) << why;
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  auto loaded = load_udp_key(path, &why);
  ASSERT_TRUE(loaded) << why;
  EXPECT_EQ(*loaded, k);
  ::chmod(path.c_str(), 0644);
  EXPECT_FALSE(load_udp_key(path, &why));
  EXPECT_NE(why.find("chmod 600"), std::string::npos) << why;
  EXPECT_NE(why.find(path), std::string::npos) << why;
  EXPECT_FALSE(load_udp_key(dir + "/none.key", &why));
  EXPECT_NE(why.find("none.key"), std::string::npos) << why;
  { std::ofstream(dir + "/short.key") << "abcd\n"; }
  ::chmod((dir + "/short.key").c_str(), 0600);
  EXPECT_FALSE(load_udp_key(dir + "/short.key", &why));
  EXPECT_NE(why.find("short.key: expected 64 hex digits"), std::string::npos) << why;

  auto r1 = random_udp_key(&why), r2 = random_udp_key(&why);
  ASSERT_TRUE(r1 && r2) << why;
  EXPECT_NE(*r1, *r2);
}

TEST(UdpAuth, Loopback) {
  EXPECT_TRUE(is_loopback_address("127.0.0.1"));
  EXPECT_TRUE(is_loopback_address("127.5.0.9"));
  EXPECT_FALSE(is_loopback_address("0.0.0.0"));
  EXPECT_FALSE(is_loopback_address("192.168.1.2"));
  EXPECT_FALSE(is_loopback_address("localhost"));
}

TEST(UdpAuthSource, NetworkAddressNeedsAKey) {
  UdpSkeletonSource open(0, "0.0.0.0");
  EXPECT_EQ(open.status().state, SourceState::Unavailable);
  EXPECT_NE(open.status().message.find("pairing key"), std::string::npos) << open.status().message;
  EXPECT_TRUE(open.poll().empty());
  UdpSkeletonSource keyed(0, "0.0.0.0", key_of(3));
  EXPECT_NE(keyed.status().state, SourceState::Unavailable) << keyed.status().message;
}

TEST(UdpAuthSource, AcceptsSignedDropsForgedReplayedAndUnsigned) {
  const UdpKey k = key_of(4);
  UdpSkeletonSource src(0, "127.0.0.1", k);
  ASSERT_NE(src.status().state, SourceState::Unavailable) << src.status().message;
  ASSERT_TRUE(src.authenticated());
  const test_support::LoopbackSender sender(src.port());
  auto send = [&](const std::vector<uint8_t>& b) { sender.send(b); };
  const auto first = encode_signed_udp_packet(100, 1.0, {palm(Hand::Right, 0.1)}, k);
  send(first);
  send(first);                                                                    // replayed
  send(encode_signed_udp_packet(101, 1.1, {palm(Hand::Right, 0.5)}, key_of(5)));  // wrong key
  send(encode_udp_packet(102, 1.2, {palm(Hand::Right, 0.5)}));                    // unsigned
  auto forged = encode_signed_udp_packet(103, 1.3, {palm(Hand::Right, 0.2)}, k);
  forged[kUdpHeaderSize + 24] ^= 0x01;  // the position changed after signing
  send(forged);
  send(encode_signed_udp_packet(99, 1.4, {palm(Hand::Right, 0.5)}, k));  // an older sequence
  send(encode_signed_udp_packet(104, 1.5, {palm(Hand::Left, 0.2)}, k));
  std::vector<HandFrame> got;
  for (int i = 0; i < 100 && src.stats().received < 7; ++i) {
    for (auto& f : src.poll()) got.push_back(f);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].hand, Hand::Right);
  EXPECT_NEAR(got[0].palm.position.x(), 0.1, 1e-6);
  EXPECT_EQ(got[1].hand, Hand::Left);
  EXPECT_EQ(src.stats().accepted, 2u);
  EXPECT_EQ(src.stats().replayed, 2u);
  EXPECT_EQ(src.stats().forged, 3u);
  EXPECT_EQ(src.stats().malformed, 0u);
  EXPECT_NE(src.status().message.find("3 forged, 2 replayed"), std::string::npos)
      << src.status().message;
}
