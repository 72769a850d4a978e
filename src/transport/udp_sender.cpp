#include "udp_sender.hpp"

#include <arpa/inet.h>
#include <fastrtps/utils/IPLocator.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

namespace tomomap::transport {

using eprosima::fastrtps::rtps::IPLocator;

UdpSender::UdpSender() {
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd_ < 0) throw std::runtime_error(std::string("cannot open a UDP socket: ") + std::strerror(errno));
  const int buffer = 1 << 20;  // as Fast DDS's UDP transport here (participant.cpp)
  ::setsockopt(fd_, SOL_SOCKET, SO_SNDBUF, &buffer, sizeof buffer);
}

UdpSender::~UdpSender() {
  if (fd_ >= 0) ::close(fd_);
}

bool UdpSender::send(const uint8_t* buffer, size_t size, const eprosima::fastrtps::rtps::Locator_t& destination) const {
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<uint16_t>(IPLocator::getPhysicalPort(destination)));
  std::memcpy(&to.sin_addr, destination.address + 12, 4);  // an IPv4 locator keeps its address in the last 4 bytes
  return ::sendto(fd_, buffer, size, MSG_NOSIGNAL, reinterpret_cast<const sockaddr*>(&to), sizeof to) ==
         static_cast<ssize_t>(size);
}

size_t withoutStatistics(const uint8_t* buffer, size_t size) {
  constexpr size_t kHeader = 20, kStatistics = 4 + 56;
  constexpr uint8_t kStatisticsId = 0x80;
  if (size < kHeader + kStatistics || buffer[size - kStatistics] != kStatisticsId) return size;
  const uint8_t flags = buffer[size - kStatistics + 1];
  const uint8_t* length = buffer + size - kStatistics + 2;
  const size_t body = (flags & 1) ? (length[0] | length[1] << 8) : (length[0] << 8 | length[1]);
  return body == kStatistics - 4 ? size - kStatistics : size;
}

}  // namespace tomomap::transport
