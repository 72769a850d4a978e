// What leaves the paced transport's own socket: the message less Fast DDS's
// statistics submessage, to the locator's address and port.
#include <arpa/inet.h>
#include <fastrtps/utils/IPLocator.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <vector>

#include "transport/udp_sender.hpp"

using namespace tomomap::transport;
using eprosima::fastrtps::rtps::IPLocator;
using eprosima::fastrtps::rtps::Locator_t;

namespace {

/// An RTPS message: the 20-byte header, one submessage of `body` bytes, and
/// a statistics submessage (id 0x80, 56 bytes of body) when asked.
std::vector<uint8_t> message(size_t body, bool statistics, uint8_t statistics_length = 56) {
  std::vector<uint8_t> m = {'R', 'T', 'P', 'S', 2, 3, 1, 15};
  m.resize(20, 7);
  m.insert(m.end(), {0x15, 0x01, static_cast<uint8_t>(body & 0xff), static_cast<uint8_t>(body >> 8)});
  for (size_t i = 0; i < body; ++i) m.push_back(static_cast<uint8_t>(i));
  if (statistics) {
    m.insert(m.end(), {0x80, 0x01, statistics_length, 0});
    m.resize(m.size() + 56, 0xab);
  }
  return m;
}

}  // namespace

TEST(UdpSender, TheStatisticsSubmessageStaysBehind) {
  const auto with = message(1000, true);
  EXPECT_EQ(withoutStatistics(with.data(), with.size()), 20u + 4 + 1000);
  const auto without = message(1000, false);
  EXPECT_EQ(withoutStatistics(without.data(), without.size()), without.size()) << "nothing to take off";
  const auto odd = message(1000, true, 40);
  EXPECT_EQ(withoutStatistics(odd.data(), odd.size()), odd.size()) << "not a statistics submessage's length";
  const auto tiny = message(0, false);
  EXPECT_EQ(withoutStatistics(tiny.data(), tiny.size()), tiny.size());
}

TEST(UdpSender, ADatagramReachesTheLocatorsAddressAndPort) {
  const int rx = ::socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(rx, 0);
  sockaddr_in at{};
  at.sin_family = AF_INET;
  at.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(rx, reinterpret_cast<sockaddr*>(&at), sizeof at), 0);
  socklen_t len = sizeof at;
  ASSERT_EQ(::getsockname(rx, reinterpret_cast<sockaddr*>(&at), &len), 0);

  Locator_t to;
  to.kind = LOCATOR_KIND_UDPv4;
  IPLocator::setIPv4(to, "127.0.0.1");
  IPLocator::setPhysicalPort(to, ntohs(at.sin_port));
  const auto m = message(300, true);
  UdpSender sender;
  ASSERT_TRUE(sender.send(m.data(), withoutStatistics(m.data(), m.size()), to));

  pollfd p{rx, POLLIN, 0};
  ASSERT_EQ(::poll(&p, 1, 10000), 1) << "nothing arrived within 10 s";
  std::vector<uint8_t> got(2000);
  const ssize_t n = ::recv(rx, got.data(), got.size(), 0);
  ::close(rx);
  ASSERT_EQ(n, static_cast<ssize_t>(20 + 4 + 300));
  got.resize(static_cast<size_t>(n));
  EXPECT_TRUE(std::equal(got.begin(), got.end(), m.begin()));
}
