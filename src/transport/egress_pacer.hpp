#pragma once
// The hard cap under the budget: every datagram the participant sends, of any
// kind, waits for its turn on a virtual link running at the pacer's rate
// (docs/protocol.md, "A pacer under everything").
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>

namespace tomomap::transport {

constexpr size_t kUdpHeader = 8, kIpv4Header = 20, kEthernetHeader = 14;
constexpr size_t kEthernetPayload = 1500;  ///< an IPv4 packet in one frame
/// The largest UDP payload that IP does not fragment on Ethernet (1472).
constexpr size_t kUdpPayloadInOneFrame = kEthernetPayload - kIpv4Header - kUdpHeader;

/// Bytes a UDP datagram with this payload puts on an Ethernet link: UDP, IPv4
/// and Ethernet headers, and the IPv4 and Ethernet headers again for every
/// further fragment of a datagram larger than one frame.
size_t wireBytes(size_t udp_payload);

/// A strict pacer: datagrams leave one after another at `bytes_per_s`, each
/// occupying the link for its wire bytes / rate, with no credit saved while
/// idle. Any window of T seconds therefore holds at most rate x T plus the
/// one datagram that started last. Thread-safe.
class EgressPacer {
 public:
  using Clock = std::chrono::steady_clock;

  explicit EgressPacer(double bytes_per_s);

  /// Waits until the link is free and runs `send_one`, which sends one
  /// datagram and returns the wire bytes that left (0 if none did). Senders
  /// take turns. When the link is not free by `deadline`, nothing is sent and
  /// the answer is false: the caller treats it as a datagram lost on the link.
  bool send(Clock::time_point deadline, const std::function<size_t()>& send_one);

  /// When the next datagram may leave, asked at `now`.
  Clock::time_point freeAt(Clock::time_point now) const;
  /// A datagram of `wire_bytes` left at `at`: the link is busy for its bytes / rate.
  void sent(size_t wire_bytes, Clock::time_point at);

  uint64_t sentBytes() const;
  uint64_t refusedDatagrams() const;

 private:
  const double bytes_per_s_;
  std::timed_mutex turn_;        ///< one sender at a time, waiting included
  mutable std::mutex state_;     ///< guards the fields below
  Clock::time_point free_at_{};  ///< when the link is free again
  uint64_t sent_bytes_ = 0;
  uint64_t refused_ = 0;
};

}  // namespace tomomap::transport
