// Authenticated UDP skeleton packets (version 2) and the pairing key, see docs/tracking.md.
// A signed packet is a version-1 packet with the version field set to 2 and an HMAC-SHA256 tag
// (32 bytes) appended, computed with the pairing key over every byte before it (header, sequence
// number, timestamp and hands). The receiver checks the tag before it parses anything else, then
// the sequence number (UdpSkeletonSource drops a sequence number it has seen or passed: replay).
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tracking/udp_source.hpp"

namespace drape::tracking {

inline constexpr uint16_t kUdpSignedVersion = 2;
inline constexpr size_t kUdpTagSize = 32;  // HMAC-SHA256
inline constexpr size_t kUdpMaxSignedPacket = kUdpMaxPacket + kUdpTagSize;

using UdpKey = std::array<uint8_t, 32>;

enum class UdpAuth {
  Ok,
  Malformed,  // not a packet of this format (too short or long, bad magic, bad fields)
  Forged,     // unsigned (version 1) or the tag does not match the key
};

// Checks the tag of a signed packet with `key`, then parses it (as parse_udp_packet, version 2).
UdpAuth verify_signed_udp_packet(const uint8_t* data, size_t size, const UdpKey& key,
                                 UdpPacket& out, std::string* why);
// Encodes and signs a packet (version 2).
std::vector<uint8_t> encode_signed_udp_packet(uint32_t sequence, double timestamp,
                                              const std::vector<HandFrame>& hands,
                                              const UdpKey& key);
// HMAC-SHA256 of data with key (the tag of a signed packet over its first bytes).
std::array<uint8_t, kUdpTagSize> udp_tag(const uint8_t* data, size_t size, const UdpKey& key);

// 32 bytes from the operating system's random source (OpenSSL RAND_bytes).
std::optional<UdpKey> random_udp_key(std::string* why);
// The key as 64 lowercase hex digits, and back (surrounding white space ignored).
std::string udp_key_hex(const UdpKey& key);
std::optional<UdpKey> parse_udp_key_hex(const std::string& text, std::string* why);
// The key file: the 64 hex digits and a newline, readable by its owner only. Loading refuses a
// file that others may read or write ("chmod 600"); errors name the file.
std::optional<UdpKey> load_udp_key(const std::string& path, std::string* why);
// Writes the key file with permissions 0600 (its folder created with 0700 when missing).
bool save_udp_key(const std::string& path, const UdpKey& key, std::string* why);

// Whether an IPv4 address in dotted form is a loopback address (127.0.0.0/8).
bool is_loopback_address(const std::string& address);

}  // namespace drape::tracking
