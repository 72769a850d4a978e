#pragma once
// Sends UDP datagrams to IPv4 locators from a socket of its own: what the
// paced transport uses instead of Fast DDS's UDP transport, whose send writes
// Fast DDS's statistics into the last 56 bytes of every message and sends
// them (docs/protocol.md, "What leaves").
#include <fastdds/rtps/common/Locator.h>

#include <cstddef>
#include <cstdint>

namespace tomomap::transport {

class UdpSender {
 public:
  UdpSender();  ///< an unbound IPv4 UDP socket; throws std::runtime_error if none can be opened
  ~UdpSender();
  UdpSender(const UdpSender&) = delete;
  UdpSender& operator=(const UdpSender&) = delete;

  /// Sends `size` bytes to `destination` (a UDPv4 locator); false if the
  /// kernel refused them (a full socket buffer drops, as a full socket would).
  bool send(const uint8_t* buffer, size_t size, const eprosima::fastrtps::rtps::Locator_t& destination) const;

 private:
  int fd_ = -1;
};

/// The bytes of an RTPS message worth sending: without the statistics
/// submessage (id 0x80, 56 bytes of body) Debian's Fast DDS ends every message
/// with. Receivers read it only to time the network; it is 60 bytes of every
/// datagram (a third of a heartbeat's).
size_t withoutStatistics(const uint8_t* buffer, size_t size);

}  // namespace tomomap::transport
