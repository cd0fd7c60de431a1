// External skeleton stream over UDP (a Kinect SDK or any body tracker on another PC).
// Packet format (little-endian), see docs/tracking.md:
//   header 24 bytes: u32 magic 'DRHS' (0x53485244), u16 version (1), u16 flags (0),
//                    u32 sequence, f64 timestamp (sender seconds), u8 hand_count (0..2), u8[3] 0
//   per hand: u8 hand (0 left, 1 right), u8 tracked (0/1), u8 joint_count (1 = palm only,
//             26 = XR_EXT_hand_tracking order), u8 0, f32 confidence (0..1),
//             f32[4] palm orientation (x, y, z, w), f32[3] * joint_count positions (m)
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tracking/hand_source.hpp"

namespace drape::tracking {

inline constexpr uint32_t kUdpMagic = 0x53485244;  // "DRHS" little-endian
inline constexpr uint16_t kUdpVersion = 1;
inline constexpr size_t kUdpHeaderSize = 24;
inline constexpr size_t kUdpMaxPacket = kUdpHeaderSize + 2 * (8 + 16 + 12 * kJointCount);
inline constexpr double kUdpMaxCoord = 10.0;  // m: positions beyond are rejected

struct UdpPacket {
  uint32_t sequence = 0;
  double timestamp = 0;
  std::vector<HandFrame> hands;
};

// Parses and validates one datagram whose version field must be `version` (1: unsigned; the
// signed packets of udp_auth.hpp are parsed with 2 once their tag is stripped and checked). On
// failure returns false and sets `why`.
bool parse_udp_packet(const uint8_t* data, size_t size, UdpPacket& out, std::string* why,
                      uint16_t version = kUdpVersion);
// Encodes frames into a packet (used by senders, tests and the fuzz seed corpus).
std::vector<uint8_t> encode_udp_packet(uint32_t sequence, double timestamp,
                                       const std::vector<HandFrame>& hands);

// What poll() did with the datagrams it read: accepted, or dropped as malformed (not a valid
// packet), stale (a sequence number already seen or passed, or a timestamp older than the last
// accepted packet's), forged (with a key: unsigned, or a tag that does not match) or replayed
// (with a key: a signed packet whose sequence number was seen or passed).
struct UdpStats {
  uint64_t received = 0, accepted = 0, malformed = 0, stale = 0, forged = 0, replayed = 0;
  std::string last_error;
  uint64_t dropped() const { return malformed + stale + forged + replayed; }
};

class UdpSkeletonSource : public HandSource {
 public:
  // Binds to address:port (default loopback only). port 0 picks a free port (see port()).
  // With a pairing key (32 bytes) only signed packets (udp_auth.hpp) are accepted; without one
  // only unsigned packets, and only on a loopback address: any other address leaves the source
  // Unavailable (a stream from the network must be authenticated).
  explicit UdpSkeletonSource(uint16_t port, const std::string& address = "127.0.0.1",
                             std::optional<std::array<uint8_t, 32>> key = std::nullopt);
  ~UdpSkeletonSource() override;
  UdpSkeletonSource(const UdpSkeletonSource&) = delete;
  UdpSkeletonSource& operator=(const UdpSkeletonSource&) = delete;
  std::string name() const override { return "udp"; }
  // Drains the socket (non-blocking); frames get the local receive time.
  std::vector<HandFrame> poll() override;
  SourceStatus status() const override;
  uint16_t port() const { return port_; }
  const UdpStats& stats() const { return stats_; }
  bool authenticated() const { return key_.has_value(); }

 private:
  int fd_ = -1;
  uint16_t port_ = 0;
  std::string error_;
  UdpStats stats_;
  std::optional<std::array<uint8_t, 32>> key_;
  bool have_seq_ = false;
  uint32_t last_seq_ = 0;
  double last_timestamp_ = 0;
};

}  // namespace drape::tracking
