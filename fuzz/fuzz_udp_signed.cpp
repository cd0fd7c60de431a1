// libFuzzer target for the signed UDP packets (tracking/udp_auth.cpp): the tag check and the
// parser behind it. The key is fixed (bytes 0, 1, ..., 31) so that the seeds in
// fuzz/corpus/udp_signed/ (signed packets as sent) pass the check. Each input is checked twice:
// as it is (a mutated packet must be refused unless its tag still matches), and with its tag
// replaced by the right one (the fuzzer's mutations then reach the parser behind the check).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "tracking/udp_auth.hpp"

namespace {
using namespace drape::tracking;

UdpKey fixed_key() {
  UdpKey k{};
  for (size_t i = 0; i < k.size(); ++i) k[i] = static_cast<uint8_t>(i);
  return k;
}

void check_accepted(const UdpPacket& p) {
  if (p.hands.size() > 2) __builtin_trap();
  for (const auto& h : p.hands)
    if (!h.palm.position.allFinite() || h.confidence < 0 || h.confidence > 1) __builtin_trap();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const UdpKey key = fixed_key();
  UdpPacket p;
  std::string why;
  if (verify_signed_udp_packet(data, size, key, p, &why) == UdpAuth::Ok) check_accepted(p);
  if (size < kUdpTagSize) return 0;
  std::vector<uint8_t> resigned(data, data + size - kUdpTagSize);
  const auto tag = udp_tag(resigned.data(), resigned.size(), key);
  resigned.insert(resigned.end(), tag.begin(), tag.end());
  const UdpAuth a = verify_signed_udp_packet(resigned.data(), resigned.size(), key, p, &why);
  if (a == UdpAuth::Ok) {
    check_accepted(p);
    // One flipped bit anywhere must break the tag (or the shape).
    resigned[size / 2] ^= 1;
    if (verify_signed_udp_packet(resigned.data(), resigned.size(), key, p, &why) == UdpAuth::Ok)
      __builtin_trap();
  }
  return 0;
}
