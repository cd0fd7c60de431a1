#include "tracking/udp_auth.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <openssl/crypto.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <openssl/rand.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace drape::tracking {

namespace {
bool fail(std::string* why, const std::string& m) {
  if (why) *why = m;
  return false;
}
std::string openssl_error() {
  const unsigned long e = ERR_get_error();
  if (e == 0) return "unknown OpenSSL error";
  char b[256];
  ERR_error_string_n(e, b, sizeof b);
  return b;
}
}  // namespace

std::array<uint8_t, kUdpTagSize> udp_tag(const uint8_t* data, size_t size, const UdpKey& key) {
  std::array<uint8_t, kUdpTagSize> tag{};
  unsigned int len = 0;
  HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()), data, size, tag.data(), &len);
  return tag;
}

UdpAuth verify_signed_udp_packet(const uint8_t* d, size_t n, const UdpKey& key, UdpPacket& out,
                                 std::string* why) {
  // Cheap shape checks first, so that the reason names what is wrong; the tag before any field
  // is trusted.
  if (n < kUdpHeaderSize + kUdpTagSize) {
    fail(why, "truncated signed packet (" + std::to_string(n) + " bytes)");
    return UdpAuth::Malformed;
  }
  if (n > kUdpMaxSignedPacket) {
    fail(why, "oversized packet (" + std::to_string(n) + " bytes)");
    return UdpAuth::Malformed;
  }
  uint32_t magic = 0;
  uint16_t version = 0;
  std::memcpy(&magic, d, 4);
  std::memcpy(&version, d + 4, 2);
  if (magic != kUdpMagic) {
    fail(why, "bad magic");
    return UdpAuth::Malformed;
  }
  if (version == kUdpVersion) {
    fail(why, "unsigned packet (version 1): this stream needs signed packets (version 2)");
    return UdpAuth::Forged;
  }
  if (version != kUdpSignedVersion) {
    fail(why, "unsupported version " + std::to_string(version));
    return UdpAuth::Malformed;
  }
  const size_t body = n - kUdpTagSize;
  const auto tag = udp_tag(d, body, key);
  if (CRYPTO_memcmp(tag.data(), d + body, kUdpTagSize) != 0) {
    fail(why, "bad signature (forged, or signed with another key)");
    return UdpAuth::Forged;
  }
  if (!parse_udp_packet(d, body, out, why, kUdpSignedVersion)) return UdpAuth::Malformed;
  return UdpAuth::Ok;
}

std::vector<uint8_t> encode_signed_udp_packet(uint32_t sequence, double timestamp,
                                              const std::vector<HandFrame>& hands,
                                              const UdpKey& key) {
  std::vector<uint8_t> b = encode_udp_packet(sequence, timestamp, hands);
  const uint16_t v = kUdpSignedVersion;
  std::memcpy(b.data() + 4, &v, 2);
  const auto tag = udp_tag(b.data(), b.size(), key);
  b.insert(b.end(), tag.begin(), tag.end());
  return b;
}

std::optional<UdpKey> random_udp_key(std::string* why) {
  UdpKey k{};
  if (RAND_bytes(k.data(), static_cast<int>(k.size())) != 1) {
    fail(why, "no random bytes: " + openssl_error());
    return std::nullopt;
  }
  return k;
}

std::string udp_key_hex(const UdpKey& key) {
  static const char* digits = "0123456789abcdef";
  std::string s;
  for (uint8_t b : key) {
    s += digits[b >> 4];
    s += digits[b & 15];
  }
  return s;
}

std::optional<UdpKey> parse_udp_key_hex(const std::string& text, std::string* why) {
  size_t a = 0, e = text.size();
  while (a < e && std::isspace(static_cast<unsigned char>(text[a]))) ++a;
  while (e > a && std::isspace(static_cast<unsigned char>(text[e - 1]))) --e;
  const std::string hex = text.substr(a, e - a);
  if (hex.size() != 2 * UdpKey().size()) {
    fail(why, "expected 64 hex digits, got " + std::to_string(hex.size()) + " characters");
    return std::nullopt;
  }
  auto nibble = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    return -1;
  };
  UdpKey k{};
  for (size_t i = 0; i < k.size(); ++i) {
    const int hi = nibble(hex[2 * i]), lo = nibble(hex[2 * i + 1]);
    if (hi < 0 || lo < 0) {
      fail(why, "not a hex digit at character " + std::to_string(2 * i + (hi < 0 ? 1 : 2)));
      return std::nullopt;
    }
    k[i] = static_cast<uint8_t>(hi * 16 + lo);
  }
  return k;
}

std::optional<UdpKey> load_udp_key(const std::string& path, std::string* why) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    fail(why, path + ": " + std::strerror(errno));
    return std::nullopt;
  }
  if (!S_ISREG(st.st_mode)) {
    fail(why, path + ": not a regular file");
    return std::nullopt;
  }
  if (st.st_mode & 077) {
    char mode[16];
    std::snprintf(mode, sizeof mode, "%03o", static_cast<unsigned>(st.st_mode & 0777));
    fail(why, path + ": permissions " + std::string(mode) +
                  " let other users read the key (chmod 600 " + path + ")");
    return std::nullopt;
  }
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  if (!in) {
    fail(why, path + ": cannot read");
    return std::nullopt;
  }
  std::string err;
  auto k = parse_udp_key_hex(ss.str(), &err);
  if (!k) fail(why, path + ": " + err);
  return k;
}

bool save_udp_key(const std::string& path, const UdpKey& key, std::string* why) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(path).parent_path();
  std::error_code ec;
  if (!dir.empty() && !fs::exists(dir, ec)) {
    fs::create_directories(dir, ec);
    if (ec) return fail(why, dir.string() + ": " + ec.message());
    fs::permissions(dir, fs::perms::owner_all, ec);
  }
  // Created 0600 (the umask can only narrow it) and set to 0600 when it existed.
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) return fail(why, path + ": " + std::strerror(errno));
  const std::string text = udp_key_hex(key) + "\n";
  const bool ok = ::fchmod(fd, 0600) == 0 &&
                  ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  const int err = errno;
  ::close(fd);
  if (!ok) return fail(why, path + ": " + std::strerror(err));
  return true;
}

bool is_loopback_address(const std::string& address) {
  in_addr a{};
  if (::inet_pton(AF_INET, address.c_str(), &a) != 1) return false;
  return (ntohl(a.s_addr) >> 24) == 127;
}

}  // namespace drape::tracking
