// A UDP socket that sends datagrams to a port on 127.0.0.1 (the UDP source tests' sender).
#pragma once
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <vector>

namespace drape::tracking::test_support {

class LoopbackSender {
 public:
  explicit LoopbackSender(uint16_t port) : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
    to_.sin_family = AF_INET;
    to_.sin_port = htons(port);
    ::inet_pton(AF_INET, "127.0.0.1", &to_.sin_addr);
  }
  ~LoopbackSender() {
    if (fd_ >= 0) ::close(fd_);
  }
  LoopbackSender(const LoopbackSender&) = delete;
  LoopbackSender& operator=(const LoopbackSender&) = delete;
  void send(const std::vector<uint8_t>& b) const {
    ::sendto(fd_, b.data(), b.size(), 0, reinterpret_cast<const sockaddr*>(&to_), sizeof to_);
  }

 private:
  int fd_;
  sockaddr_in to_{};
};

}  // namespace drape::tracking::test_support
