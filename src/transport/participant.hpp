#pragma once
// A DDS participant that talks only to the peers named in the config: UDPv4
// unicast on explicit ports, multicast and shared memory off, a flow
// controller that shares the configured bandwidth budget between the slice
// stream's receivers, and a pacer under all of it that holds the budget for
// every datagram sent (docs/protocol.md).
#include <memory>
#include <string>

#include "link_budget.hpp"

namespace eprosima::fastdds::dds {
class DomainParticipant;
class DomainParticipantListener;
}  // namespace eprosima::fastdds::dds

namespace tomomap::transport {

class EgressPacer;

/// The flow controller's name (a static string: Fast DDS keeps the pointer).
extern const char* const kFlowControllerName;

/// The participant name an agent's daemon takes: "tomomapd/<agent>".
std::string participantName(const std::string& agent);

/// Creates the participant; throws std::runtime_error naming the cause. Every
/// datagram it sends passes `pacer` (made for pacedKbps(config)).
/// `listener` is attached at creation: set afterwards, it would miss the peers
/// discovered in between (a peer already running is found at once).
eprosima::fastdds::dds::DomainParticipant* createParticipant(
    const TransportConfig& config, std::shared_ptr<EgressPacer> pacer,
    eprosima::fastdds::dds::DomainParticipantListener* listener = nullptr);

}  // namespace tomomap::transport
