#include "tracking/udp_source.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "tracking/udp_auth.hpp"

namespace drape::tracking {

namespace {
template <class T>
T rd(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}
template <class T>
void wr(std::vector<uint8_t>& b, T v) {
  const auto* p = reinterpret_cast<const uint8_t*>(&v);
  b.insert(b.end(), p, p + sizeof(T));
}
bool fail(std::string* why, const std::string& m) {
  if (why) *why = m;
  return false;
}
double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

bool parse_udp_packet(const uint8_t* d, size_t n, UdpPacket& out, std::string* why,
                      uint16_t version) {
  static_assert(sizeof(float) == 4 && sizeof(double) == 8);
  if (n < kUdpHeaderSize) return fail(why, "truncated header (" + std::to_string(n) + " bytes)");
  if (n > kUdpMaxPacket) return fail(why, "oversized packet (" + std::to_string(n) + " bytes)");
  if (rd<uint32_t>(d) != kUdpMagic) return fail(why, "bad magic");
  if (const uint16_t v = rd<uint16_t>(d + 4); v != version)
    return fail(why, v == 2 && version == 1
                         ? "signed packet (version 2) but no pairing key here (--hands-key)"
                         : "unsupported version " + std::to_string(v));
  out.sequence = rd<uint32_t>(d + 8);
  out.timestamp = rd<double>(d + 12);
  if (!std::isfinite(out.timestamp)) return fail(why, "timestamp not finite");
  const int hands = d[20];
  if (hands > 2) return fail(why, "hand_count " + std::to_string(hands) + " > 2");
  out.hands.clear();
  size_t off = kUdpHeaderSize;
  bool seen[2] = {false, false};
  for (int h = 0; h < hands; ++h) {
    if (off + 24 > n) return fail(why, "truncated hand record");
    const int which = d[off], tracked = d[off + 1], joints = d[off + 2];
    if (which > 1) return fail(why, "hand index " + std::to_string(which));
    if (seen[which]) return fail(why, "duplicate hand");
    seen[which] = true;
    if (tracked > 1) return fail(why, "tracked flag not 0/1");
    if (joints != 1 && joints != kJointCount)
      return fail(why, "joint_count " + std::to_string(joints) + " (must be 1 or 26)");
    HandFrame f;
    f.hand = static_cast<Hand>(which);
    f.tracked = tracked == 1;
    f.time = out.timestamp;
    const float conf = rd<float>(d + off + 4);
    if (!(conf >= 0.f && conf <= 1.f)) return fail(why, "confidence out of [0,1]");
    f.confidence = conf;
    float q[4];
    for (int k = 0; k < 4; ++k) q[k] = rd<float>(d + off + 8 + 4 * k);
    const double qn = std::sqrt(double(q[0]) * q[0] + double(q[1]) * q[1] + double(q[2]) * q[2] +
                                double(q[3]) * q[3]);
    if (!(qn > 0.5 && qn < 1.5)) return fail(why, "palm orientation not a unit quaternion");
    f.palm.orientation = Quat(q[3] / qn, q[0] / qn, q[1] / qn, q[2] / qn);
    off += 24;
    if (off + 12 * size_t(joints) > n) return fail(why, "truncated joints");
    for (int j = 0; j < joints; ++j) {
      Vec3 p;
      for (int k = 0; k < 3; ++k) p(k) = rd<float>(d + off + 4 * k);
      if (!p.allFinite()) return fail(why, "joint position not finite");
      if (p.cwiseAbs().maxCoeff() > kUdpMaxCoord) return fail(why, "joint position out of range");
      f.joints[j] = p;
      off += 12;
    }
    f.has_joints = joints == kJointCount;
    f.palm.position = f.joints[0];
    out.hands.push_back(f);
  }
  if (off != n) return fail(why, "trailing bytes (" + std::to_string(n - off) + ")");
  return true;
}

std::vector<uint8_t> encode_udp_packet(uint32_t seq, double ts,
                                       const std::vector<HandFrame>& hands) {
  std::vector<uint8_t> b;
  wr<uint32_t>(b, kUdpMagic);
  wr<uint16_t>(b, kUdpVersion);
  wr<uint16_t>(b, 0);
  wr<uint32_t>(b, seq);
  wr<double>(b, ts);
  wr<uint8_t>(b, static_cast<uint8_t>(hands.size()));
  for (int i = 0; i < 3; ++i) wr<uint8_t>(b, 0);
  for (const auto& f : hands) {
    const int joints = f.has_joints ? kJointCount : 1;
    wr<uint8_t>(b, static_cast<uint8_t>(f.hand));
    wr<uint8_t>(b, f.tracked ? 1 : 0);
    wr<uint8_t>(b, static_cast<uint8_t>(joints));
    wr<uint8_t>(b, 0);
    wr<float>(b, static_cast<float>(f.confidence));
    const Quat& q = f.palm.orientation;
    for (double v : {q.x(), q.y(), q.z(), q.w()}) wr<float>(b, static_cast<float>(v));
    for (int j = 0; j < joints; ++j) {
      const Vec3 p = f.has_joints ? f.joints[j] : f.palm.position;
      for (int k = 0; k < 3; ++k) wr<float>(b, static_cast<float>(p(k)));
    }
  }
  return b;
}

UdpSkeletonSource::UdpSkeletonSource(uint16_t port, const std::string& address,
                                     std::optional<std::array<uint8_t, 32>> key)
    : key_(key) {
  if (!key_ && !is_loopback_address(address)) {
    error_ = "udp: listening on " + address +
             " needs a pairing key (drape hands pair; --hands-key FILE): only loopback is open";
    return;
  }
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    error_ = std::string("udp: socket: ") + std::strerror(errno);
    return;
  }
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  if (::inet_pton(AF_INET, address.c_str(), &a.sin_addr) != 1) {
    error_ = "udp: bad bind address '" + address + "'";
    ::close(fd_);
    fd_ = -1;
    return;
  }
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    error_ = "udp: bind " + address + ":" + std::to_string(port) + ": " + std::strerror(errno);
    ::close(fd_);
    fd_ = -1;
    return;
  }
  socklen_t len = sizeof a;
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
  port_ = ntohs(a.sin_port);
}

UdpSkeletonSource::~UdpSkeletonSource() {
  if (fd_ >= 0) ::close(fd_);
}

std::vector<HandFrame> UdpSkeletonSource::poll() {
  std::vector<HandFrame> frames;
  if (fd_ < 0) return frames;
  uint8_t buf[2048];
  auto drop = [this](uint64_t& counter, std::string why) {
    ++counter;
    stats_.last_error = std::move(why);
  };
  for (;;) {
    // MSG_TRUNC: the datagram's real length, so that an oversized one is named as such.
    const ssize_t n = ::recv(fd_, buf, sizeof buf, MSG_TRUNC);
    if (n < 0) break;  // EAGAIN: drained (other errors: nothing more to read either)
    ++stats_.received;
    const size_t size = static_cast<size_t>(n);
    UdpPacket p;
    std::string why;
    if (size > sizeof buf) {
      drop(stats_.malformed, "oversized packet (" + std::to_string(size) + " bytes)");
      continue;
    }
    if (key_) {
      const UdpAuth a = verify_signed_udp_packet(buf, size, *key_, p, &why);
      if (a == UdpAuth::Forged) drop(stats_.forged, why);
      if (a == UdpAuth::Malformed) drop(stats_.malformed, why);
      if (a != UdpAuth::Ok) continue;
    } else if (!parse_udp_packet(buf, size, p, &why)) {
      drop(stats_.malformed, why);
      continue;
    }
    // Sequence numbers: drop duplicates and reordered (older) packets; wrap-around safe. With a
    // key this is the replay check: a signed packet seen before never counts twice.
    if (have_seq_ && static_cast<int32_t>(p.sequence - last_seq_) <= 0) {
      drop(key_ ? stats_.replayed : stats_.stale,
           (key_ ? "replayed sequence number " : "out-of-order sequence number ") +
               std::to_string(p.sequence) + " (last " + std::to_string(last_seq_) + ")");
      continue;
    }
    // Timestamps: a packet must not be older than the last accepted one (a sender that resends
    // old poses under new sequence numbers, or a stream mixed from two senders).
    if (have_seq_ && p.timestamp < last_timestamp_) {
      char b[96];
      std::snprintf(b, sizeof b, "old timestamp %.3f s (last accepted %.3f s)", p.timestamp,
                    last_timestamp_);
      drop(stats_.stale, b);
      continue;
    }
    have_seq_ = true;
    last_seq_ = p.sequence;
    last_timestamp_ = p.timestamp;
    ++stats_.accepted;
    const double t = now_s();
    for (auto& f : p.hands) {
      f.time = t;
      frames.push_back(f);
    }
  }
  return frames;
}

SourceStatus UdpSkeletonSource::status() const {
  if (fd_ < 0) return {SourceState::Unavailable, error_};
  std::string m = "udp: port " + std::to_string(port_) + (key_ ? " (signed)" : "") + ", " +
                  std::to_string(stats_.accepted) + " accepted, " +
                  std::to_string(stats_.malformed) + " malformed, " + std::to_string(stats_.stale) +
                  " stale";
  if (key_)
    m += ", " + std::to_string(stats_.forged) + " forged, " + std::to_string(stats_.replayed) +
         " replayed";
  if (!stats_.last_error.empty()) m += " (last: " + stats_.last_error + ")";
  return {stats_.accepted ? SourceState::Ok : SourceState::NoData, m};
}

}  // namespace drape::tracking
