#include "paced_transport.hpp"

#include <fastdds/rtps/transport/ChainingTransport.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <string_view>

#include "udp_sender.hpp"

namespace tomomap::transport {

namespace rtps = eprosima::fastdds::rtps;
using eprosima::fastrtps::rtps::Locator_t;
using eprosima::fastrtps::rtps::octet;
using eprosima::fastrtps::rtps::SenderResource;

namespace {

/// One destination as the locator range a sender resource takes.
struct OneLocator : rtps::LocatorsIterator {
  const Locator_t* at;
  explicit OneLocator(const Locator_t* l) : at(l) {}
  rtps::LocatorsIterator& operator++() override {
    ++at;
    return *this;
  }
  bool operator==(const rtps::LocatorsIterator& o) const override { return at == static_cast<const OneLocator&>(o).at; }
  bool operator!=(const rtps::LocatorsIterator& o) const override { return !(*this == o); }
  const Locator_t& operator*() const override { return *at; }
};

class PacedTransport : public rtps::ChainingTransport {
 public:
  explicit PacedTransport(const PacedTransportDescriptor& d)
      : ChainingTransport(d), descriptor_(d), own_(d.own_sender ? std::make_unique<UdpSender>() : nullptr) {}

  rtps::TransportDescriptorInterface* get_configuration() override { return &descriptor_; }

  /// Sends one datagram per destination, each when the pacer finds the link
  /// free. Fast DDS offers every message to each of its sender resources
  /// (sockets) in turn: the first offer sends it, the others are repeats().
  /// From our own socket the statistics submessage stays behind; through the
  /// chained transport (the lossy test one) only the resource whose purpose
  /// fits sends. A datagram that cannot start before its deadline is dropped,
  /// as a full socket would drop it, and the protocol repairs it like any
  /// loss on the link.
  bool send(SenderResource* low, const octet* buffer, uint32_t size, rtps::LocatorsIterator* begin,
            rtps::LocatorsIterator* end, const std::chrono::steady_clock::time_point& deadline) override {
    bool sent = false;
    // What leaves our socket, and what identifies the message among the
    // resources' offers (the statistics a chained send fills in excluded).
    const size_t bytes = withoutStatistics(buffer, size);
    const size_t message = std::hash<std::string_view>{}({reinterpret_cast<const char*>(buffer), bytes});
    for (auto& it = *begin; it != *end; ++it) {
      if (!low_level_transport_->IsLocatorSupported(*it)) continue;
      const Locator_t destination = *it;
      if (repeats(message, destination, low)) {
        sent = true;
        continue;
      }
      descriptor_.pacer->send(deadline, [&]() -> size_t {
        OneLocator first(&destination), last(&destination + 1);
        if (own_ ? !own_->send(buffer, bytes, destination) : !low->send(buffer, size, &first, &last, deadline))
          return 0;
        sent = true;
        remember(message, destination, low);
        return wireBytes(own_ ? bytes : size);
      });
    }
    return sent;
  }

  /// Whether `message` (a hash of its bytes) has left for `destination` already,
  /// offered by another of Fast DDS's sender resources: each gets every
  /// message in turn, and the first sends it from our socket (at 250 kbit/s
  /// with four receivers one turn took longer than 50 ms). The same resource
  /// offering it again is a retry Fast DDS means to send: skipping repeats
  /// within 50 ms from it too (participant announcements went twice to each
  /// peer) once kept a peer's first announcement from a participant that had
  /// just appeared, which then waited 12 s for the next one.
  bool repeats(size_t message, const Locator_t& destination, const SenderResource* low) {
    std::lock_guard<std::mutex> lock(recent_mutex_);
    const auto now = std::chrono::steady_clock::now();
    return std::any_of(recent_.begin(), recent_.end(), [&](const Sent& s) {
      return s.message == message && s.destination == destination && s.low != low && now - s.at < kOtherResourceWindow;
    });
  }
  void remember(size_t message, const Locator_t& destination, const SenderResource* low) {
    std::lock_guard<std::mutex> lock(recent_mutex_);
    recent_[next_++ % recent_.size()] = {message, destination, low, std::chrono::steady_clock::now()};
  }

  void receive(rtps::TransportReceiverInterface* next, const octet* buffer, uint32_t size, const Locator_t& local,
               const Locator_t& remote) override {
    next->OnDataReceived(buffer, size, local, remote);
  }

 private:
  /// Longer than any turn over the sender resources takes: six receivers of
  /// 1.5 kB datagrams at 64 kbit/s take 1.1 s.
  static constexpr std::chrono::seconds kOtherResourceWindow{5};
  struct Sent {
    size_t message = 0;
    Locator_t destination;
    const SenderResource* low = nullptr;
    std::chrono::steady_clock::time_point at{};
  };
  PacedTransportDescriptor descriptor_;
  std::unique_ptr<UdpSender> own_;  ///< null: send through the chained transport
  std::mutex recent_mutex_;
  std::array<Sent, 64> recent_{};  ///< the last datagrams sent, by every thread
  size_t next_ = 0;
};

}  // namespace

PacedTransportDescriptor::PacedTransportDescriptor(std::shared_ptr<rtps::TransportDescriptorInterface> udp,
                                                   std::shared_ptr<EgressPacer> p, bool own)
    : ChainingTransportDescriptor(std::move(udp)), pacer(std::move(p)), own_sender(own) {}

rtps::TransportInterface* PacedTransportDescriptor::create_transport() const { return new PacedTransport(*this); }

}  // namespace tomomap::transport
