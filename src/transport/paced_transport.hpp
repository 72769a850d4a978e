#pragma once
// Fast DDS's UDP transport with every datagram passed through an EgressPacer:
// discovery, heartbeats, acknowledgements, repairs and data alike, so the
// budget holds for all of an agent's egress, not only for what the flow
// controller schedules.
#include <fastdds/rtps/transport/ChainingTransportDescriptor.h>

#include <memory>

#include "egress_pacer.hpp"

namespace tomomap::transport {

struct PacedTransportDescriptor : eprosima::fastdds::rtps::ChainingTransportDescriptor {
  /// `own_sender`: send from a socket of our own, without the statistics
  /// submessage (udp_sender.hpp); false to send through `udp` itself (Fast
  /// DDS's lossy test transport, whose losses happen in its send).
  PacedTransportDescriptor(std::shared_ptr<eprosima::fastdds::rtps::TransportDescriptorInterface> udp,
                           std::shared_ptr<EgressPacer> pacer, bool own_sender);
  eprosima::fastdds::rtps::TransportInterface* create_transport() const override;

  std::shared_ptr<EgressPacer> pacer;
  bool own_sender = true;
};

}  // namespace tomomap::transport
