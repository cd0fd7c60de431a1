// `drape hands`: the UDP skeleton stream's tools (docs/tracking.md, "The UDP stream").
//   drape hands send TRACE [--to ADDR:PORT] [--rate HZ] [--loop] [--key FILE]
//       replays a trace file as UDP packets at the trace's timestamps (or resampled at --rate):
//       the sender a tracking pipeline on another machine mimics;
//   drape hands pair [--key FILE] [--renew]
//       makes the pairing key once (32 random bytes, a file readable by the user only) and
//       prints it in hex for the sender.
// Also the executable's side of --hands-key (hands_key.hpp).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "tracking/trace.hpp"
#include "tracking/udp_auth.hpp"
#include "tracking/udp_source.hpp"
#include "xr_app/command.hpp"
#include "xr_app/hands_key.hpp"

namespace drape::app {

namespace fs = std::filesystem;

std::string default_hands_key_path() {
  const char* xdg = std::getenv("XDG_CONFIG_HOME");
  if (xdg && *xdg) return (fs::path(xdg) / "drape" / "hands.key").string();
  const char* home = std::getenv("HOME");
  if (home && *home) return (fs::path(home) / ".config" / "drape" / "hands.key").string();
  return "";
}

void add_hands_key_option(CLI::App& cli, std::string& key_file) {
  cli.add_option("--hands-key", key_file,
                 "pairing key file of --hands udp (drape hands pair): only signed packets are "
                 "accepted (default: " +
                     default_hands_key_path() +
                     " when it exists; without a key only a loopback address may be given)")
      ->always_capture_default(false);
}

bool resolve_hands_key(const char* command, bool udp, const std::string& given,
                       const std::string& address, std::vector<uint8_t>& key) {
  key.clear();
  if (!udp) {
    if (given.empty()) return true;
    std::fprintf(stderr, "%s: --hands-key: only with --hands udp\n", command);
    return false;
  }
  std::string path = given;
  std::error_code ec;
  if (path.empty()) {
    const std::string def = default_hands_key_path();
    if (!def.empty() && fs::exists(def, ec)) path = def;
  }
  if (path.empty()) {
    if (tracking::is_loopback_address(address)) return true;
    std::fprintf(
        stderr,
        "%s: --hands udp:%s:...: listening beyond this machine needs a pairing key; run "
        "`drape hands pair` once (it writes %s and prints the key for the sender), or "
        "give --hands-key FILE\n",
        command, address.c_str(),
        default_hands_key_path().empty() ? "the key file" : default_hands_key_path().c_str());
    return false;
  }
  std::string why;
  const auto k = tracking::load_udp_key(path, &why);
  if (!k) {
    std::fprintf(stderr, "%s: --hands-key: %s\n", command, why.c_str());
    return false;
  }
  key.assign(k->begin(), k->end());
  return true;
}

namespace {

using tracking::HandFrame;

// One packet: the hands of one instant (at most one frame per hand).
struct Tick {
  double time = 0;
  std::vector<HandFrame> hands;
};

// The trace's frames grouped into packets: frames of the same time and different hands share one.
std::vector<Tick> ticks_at_trace_times(const std::vector<HandFrame>& frames) {
  std::vector<Tick> ticks;
  for (const HandFrame& f : frames) {
    const bool same = !ticks.empty() && std::abs(ticks.back().time - f.time) < 1e-9 &&
                      std::none_of(ticks.back().hands.begin(), ticks.back().hands.end(),
                                   [&](const HandFrame& g) { return g.hand == f.hand; });
    if (!same) ticks.push_back({f.time, {}});
    ticks.back().hands.push_back(f);
  }
  return ticks;
}

// A hand's frame at time t, interpolated between its frames around t (positions and confidence
// linearly, orientations by slerp); none before its first or after its last frame.
std::optional<HandFrame> hand_at(const std::vector<HandFrame>& own, double t) {
  if (own.empty() || t < own.front().time - 1e-9 || t > own.back().time + 1e-9) return std::nullopt;
  auto it = std::upper_bound(own.begin(), own.end(), t,
                             [](double x, const HandFrame& f) { return x < f.time; });
  if (it == own.begin()) return own.front();
  if (it == own.end()) return own.back();
  const HandFrame& a = *(it - 1);
  const HandFrame& b = *it;
  const double span = b.time - a.time;
  const double u = span > 0 ? (t - a.time) / span : 0.0;
  HandFrame f = a;
  f.time = t;
  f.tracked = a.tracked && b.tracked;
  f.confidence = a.confidence + (b.confidence - a.confidence) * u;
  f.palm.position = a.palm.position + (b.palm.position - a.palm.position) * u;
  f.palm.orientation = a.palm.orientation.normalized().slerp(u, b.palm.orientation.normalized());
  f.has_joints = a.has_joints && b.has_joints;
  for (int j = 0; f.has_joints && j < tracking::kJointCount; ++j)
    f.joints[j] = a.joints[j] + (b.joints[j] - a.joints[j]) * u;
  return f;
}

// The trace resampled at `rate` Hz from its first frame to its last.
std::vector<Tick> ticks_at_rate(const std::vector<HandFrame>& frames, double rate) {
  std::vector<HandFrame> own[2];
  for (const HandFrame& f : frames) own[static_cast<int>(f.hand)].push_back(f);
  std::vector<Tick> ticks;
  const double t0 = frames.front().time, t1 = frames.back().time;
  for (int64_t i = 0;; ++i) {
    const double t = t0 + static_cast<double>(i) / rate;
    if (t > t1 + 1e-9) break;
    Tick tick{t, {}};
    for (const auto& hand : own)
      if (auto f = hand_at(hand, t)) tick.hands.push_back(*f);
    if (!tick.hands.empty()) ticks.push_back(std::move(tick));
  }
  return ticks;
}

bool parse_destination(const std::string& to, sockaddr_in& a, std::string& why) {
  const size_t colon = to.rfind(':');
  if (colon == std::string::npos || colon == 0) {
    why = "expected ADDR:PORT, got '" + to + "'";
    return false;
  }
  const std::string addr = to.substr(0, colon), port = to.substr(colon + 1);
  char* end = nullptr;
  const long p = std::strtol(port.c_str(), &end, 10);
  if (port.empty() || *end != '\0' || p < 1 || p > 65535) {
    why = "bad port '" + port + "' in '" + to + "' (1..65535)";
    return false;
  }
  a = {};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(p));
  if (::inet_pton(AF_INET, addr.c_str(), &a.sin_addr) != 1) {
    why = "not an IPv4 address: '" + addr + "' in '" + to + "'";
    return false;
  }
  return true;
}

int hands_send(int argc, char** argv) {
  CLI::App cli{"Replays a trace file (docs/tracking.md) as UDP skeleton packets",
               "drape hands send"};
  cli.option_defaults()->always_capture_default();
  std::string trace, to = "127.0.0.1:9740", key_file;
  double rate = 0;
  bool loop = false;
  cli.add_option("TRACE", trace, "the trace file (# drape-trace v1)")->required();
  cli.add_option("--to", to, "where the packets go (IPv4 ADDR:PORT)");
  cli.add_option("--rate", rate,
                 "resample the trace at this rate (Hz, linear interpolation); 0: send each "
                 "frame at its own timestamp")
      ->check(CLI::Range(0.0, 1000.0));
  cli.add_flag("--loop", loop, "start over at the end, until interrupted (Ctrl-C)");
  cli.add_option("--key", key_file,
                 "sign the packets (version 2) with this pairing key file (drape hands pair); "
                 "default: unsigned (version 1)")
      ->always_capture_default(false);
  if (const int rc = parse_command_line(cli, argc, argv); rc >= 0) return rc;

  std::string why;
  const auto frames = tracking::read_trace(trace, &why);
  if (!frames) {
    std::fprintf(stderr, "drape hands send: %s\n", why.c_str());
    return 2;
  }
  if (frames->empty()) {
    std::fprintf(stderr, "drape hands send: %s: no frames\n", trace.c_str());
    return 2;
  }
  sockaddr_in dest{};
  if (!parse_destination(to, dest, why)) {
    std::fprintf(stderr, "drape hands send: --to: %s\n", why.c_str());
    return 2;
  }
  std::optional<tracking::UdpKey> key;
  if (!key_file.empty()) {
    key = tracking::load_udp_key(key_file, &why);
    if (!key) {
      std::fprintf(stderr, "drape hands send: --key: %s\n", why.c_str());
      return 2;
    }
  }
  const std::vector<Tick> ticks =
      rate > 0 ? ticks_at_rate(*frames, rate) : ticks_at_trace_times(*frames);
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    std::perror("drape hands send: socket");
    return 1;
  }
  // A loop starts one period after the trace's end: the period is 1/rate, else the trace's last
  // frame gap (at least 1 ms), so that timestamps keep increasing.
  const double first = ticks.front().time, last = ticks.back().time;
  double period = rate > 0 ? 1.0 / rate : 1e-3;
  if (rate <= 0 && ticks.size() > 1) period = std::max(1e-3, last - ticks[ticks.size() - 2].time);
  const double lap = last - first + period;
  // Sequence numbers start at the Unix time in milliseconds (mod 2^32): a restarted sender goes
  // on above its predecessor's numbers as long as it sends at most 1000 packets a second, so a
  // receiver that checks replays keeps accepting it.
  auto seq = static_cast<uint32_t>(std::chrono::duration_cast<std::chrono::milliseconds>(
                                       std::chrono::system_clock::now().time_since_epoch())
                                       .count());
  const auto start = std::chrono::steady_clock::now();
  uint64_t packets = 0, hand_frames = 0, failed = 0;
  for (int64_t round = 0; round == 0 || loop; ++round) {
    for (const Tick& tick : ticks) {
      const double ts = tick.time - first + static_cast<double>(round) * lap;
      std::this_thread::sleep_until(start + std::chrono::duration_cast<std::chrono::nanoseconds>(
                                                std::chrono::duration<double>(ts)));
      const std::vector<uint8_t> b =
          key ? tracking::encode_signed_udp_packet(seq, ts, tick.hands, *key)
              : tracking::encode_udp_packet(seq, ts, tick.hands);
      ++seq;
      if (::sendto(fd, b.data(), b.size(), 0, reinterpret_cast<const sockaddr*>(&dest),
                   sizeof dest) != static_cast<ssize_t>(b.size())) {
        if (failed++ == 0) std::perror("drape hands send: sendto");
        continue;
      }
      ++packets;
      hand_frames += tick.hands.size();
    }
  }
  ::close(fd);
  const double secs =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("drape hands send: %llu packets (%llu hand frames, %s) to %s in %.2f s",
              static_cast<unsigned long long>(packets),
              static_cast<unsigned long long>(hand_frames), key ? "signed" : "unsigned", to.c_str(),
              secs);
  if (failed) std::printf(", %llu not sent", static_cast<unsigned long long>(failed));
  std::printf("\n");
  return failed ? 1 : 0;
}

int hands_pair(int argc, char** argv) {
  CLI::App cli{"Makes the UDP stream's pairing key once and prints it in hex for the sender",
               "drape hands pair"};
  cli.option_defaults()->always_capture_default();
  std::string key_file = default_hands_key_path();
  bool renew = false;
  cli.add_option("--key", key_file, "the key file");
  cli.add_flag("--renew", renew, "replace an existing key (every sender needs the new one)");
  if (const int rc = parse_command_line(cli, argc, argv); rc >= 0) return rc;
  if (key_file.empty()) {
    std::fprintf(stderr, "drape hands pair: neither XDG_CONFIG_HOME nor HOME is set: give --key\n");
    return 2;
  }
  std::string why;
  std::error_code ec;
  if (fs::exists(key_file, ec) && !renew) {
    const auto k = tracking::load_udp_key(key_file, &why);
    if (!k) {
      std::fprintf(stderr, "drape hands pair: %s (--renew replaces it)\n", why.c_str());
      return 1;
    }
    std::fprintf(stderr,
                 "drape hands pair: the key already made, in %s (--renew makes a new one)\n",
                 key_file.c_str());
    std::printf("%s\n", tracking::udp_key_hex(*k).c_str());
    return 0;
  }
  const auto k = tracking::random_udp_key(&why);
  if (!k || !tracking::save_udp_key(key_file, *k, &why)) {
    std::fprintf(stderr, "drape hands pair: %s\n", why.c_str());
    return 1;
  }
  std::fprintf(stderr,
               "drape hands pair: a new key in %s (readable by you only); the sender signs with "
               "it (drape hands send --key FILE, or these 64 hex digits, docs/tracking.md)\n",
               key_file.c_str());
  std::printf("%s\n", tracking::udp_key_hex(*k).c_str());
  return 0;
}

int hands_command(int argc, char** argv) {
  const std::string usage =
      "usage: drape hands send TRACE [--to ADDR:PORT] [--rate HZ] [--loop] [--key FILE]\n"
      "       drape hands pair [--key FILE] [--renew]\n"
      "(drape hands send --help, drape hands pair --help list the options)\n";
  const std::string what = argc > 1 ? argv[1] : "";
  if (what == "--help" || what == "-h") {
    std::printf("%s", usage.c_str());
    return 0;
  }
  if (what == "send") return hands_send(argc - 1, argv + 1);
  if (what == "pair") return hands_pair(argc - 1, argv + 1);
  std::fprintf(stderr, "drape hands: %s\n%s",
               what.empty() ? "which tool?" : ("unknown tool '" + what + "'").c_str(),
               usage.c_str());
  return 2;
}

}  // namespace

DRAPE_COMMAND(hands, "the UDP hand stream: send a trace, pair a sender", hands_command);

}  // namespace drape::app
