// libFuzzer target for the UDP skeleton packet parser (tracking/udp_source.cpp).
#include <cstddef>
#include <cstdint>
#include <string>

#include "tracking/udp_source.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  drape::tracking::UdpPacket p;
  std::string why;
  if (drape::tracking::parse_udp_packet(data, size, p, &why)) {
    // Accepted packets must satisfy the documented ranges.
    if (p.hands.size() > 2) __builtin_trap();
    for (const auto& h : p.hands)
      if (!h.palm.position.allFinite() || h.confidence < 0 || h.confidence > 1) __builtin_trap();
  }
  return 0;
}
