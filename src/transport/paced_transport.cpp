#include "paced_transport.hpp"

#include <fastdds/rtps/transport/ChainingTransport.h>

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
  explicit PacedTransport(const PacedTransportDescriptor& d) : ChainingTransport(d), descriptor_(d) {}

  rtps::TransportDescriptorInterface* get_configuration() override { return &descriptor_; }

  /// Sends one datagram per destination, each when the pacer finds the link
  /// free. Fast DDS offers every message to each of its sender resources
  /// (sockets) in turn and only the one whose purpose fits sends it, so only
  /// what the socket really sent occupies the link (the others' turns still
  /// wait for the link to be free, which costs no throughput: the next
  /// datagram would have waited as long). A datagram that cannot
  /// start before its deadline is dropped, as a full socket would drop it,
  /// and the protocol repairs it like any loss on the link.
  bool send(SenderResource* low, const octet* buffer, uint32_t size, rtps::LocatorsIterator* begin,
            rtps::LocatorsIterator* end, const std::chrono::steady_clock::time_point& deadline) override {
    bool sent = false;
    for (auto& it = *begin; it != *end; ++it) {
      if (!low_level_transport_->IsLocatorSupported(*it)) continue;
      const Locator_t destination = *it;
      descriptor_.pacer->send(deadline, [&]() -> size_t {
        OneLocator first(&destination), last(&destination + 1);
        if (!low->send(buffer, size, &first, &last, deadline)) return 0;
        sent = true;
        return wireBytes(size);
      });
    }
    return sent;
  }

  void receive(rtps::TransportReceiverInterface* next, const octet* buffer, uint32_t size, const Locator_t& local,
               const Locator_t& remote) override {
    next->OnDataReceived(buffer, size, local, remote);
  }

 private:
  PacedTransportDescriptor descriptor_;
};

}  // namespace

PacedTransportDescriptor::PacedTransportDescriptor(std::shared_ptr<rtps::TransportDescriptorInterface> udp,
                                                   std::shared_ptr<EgressPacer> p)
    : ChainingTransportDescriptor(std::move(udp)), pacer(std::move(p)) {}

rtps::TransportInterface* PacedTransportDescriptor::create_transport() const { return new PacedTransport(*this); }

}  // namespace tomomap::transport
