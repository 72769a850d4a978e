#pragma once
// A DDS participant that talks only to the peers named in the config: UDPv4
// unicast on explicit ports, multicast and shared memory off, a flow
// controller that shares the configured bandwidth budget between the slice
// stream's receivers, and a pacer under all of it that holds the budget for
// every datagram sent (docs/protocol.md).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace eprosima::fastdds::dds {
class DomainParticipant;
class DomainParticipantListener;
}  // namespace eprosima::fastdds::dds

namespace tomomap::transport {

class EgressPacer;

struct PeerAddress {
  std::string id;
  std::string host;   ///< IPv4 address
  uint16_t port = 0;  ///< the peer's discovery port
};

/// DDS Security's files (PEM and S/MIME, docs/operations.md "A secure fleet").
/// Security is on when `ca` is set; then all but `crl` are set.
struct SecurityFiles {
  std::string ca;           ///< the fleet CA: identities and permissions documents
  std::string certificate;  ///< this agent's certificate (CN=<agent>)
  std::string private_key;  ///< its key
  std::string governance;   ///< the signed domain rules
  std::string permissions;  ///< this agent's signed grant
  std::string crl;          ///< optional: revoked certificates
  /// A digest of the files' contents when the config was read: a reload
  /// that finds other contents at the same paths (a new CRL, a renewed
  /// certificate) joins the network again with them.
  size_t contents = 0;
  bool enabled() const { return !ca.empty(); }
  bool operator==(const SecurityFiles& o) const {
    return ca == o.ca && certificate == o.certificate && private_key == o.private_key && governance == o.governance &&
           permissions == o.permissions && crl == o.crl && contents == o.contents;
  }
};

struct TransportConfig {
  std::string agent;
  int domain = 0;
  std::string address = "127.0.0.1";  ///< own IPv4 address, where peers reach us
  uint16_t discovery_port = 0;
  uint16_t data_port = 0;
  std::vector<PeerAddress> peers;
  double bandwidth_kbps = 10000;  ///< budget for all of the agent's egress [kbit/s]
  int test_drop_percent = 0;      ///< test only (daemon/test_faults.hpp): share of sent RTPS messages dropped [%]
  SecurityFiles security;
};

/// Flow-controller period [ms] with one receiver, unless it would hold fewer
/// than kSamplesPerPeriod samples (flowBaseMs).
constexpr int kFlowPeriodMs = 100;
/// The controller sends whole samples only, and one that does not fit the
/// rest of a period waits for the next: with at least this many samples a
/// period, at most about an eighth of the stream's rate goes unused.
constexpr int kSamplesPerPeriod = 8;

/// Share of the budget left to control traffic (discovery, heartbeats,
/// acknowledgements, requests, claims, estimates, announcements), which does
/// not pass the flow controller: the slice data gets the rest. It grows with
/// the receivers: each new peer costs a burst of discovery and announcements
/// (about 20 kB in the first seconds, measured) on top of a steady few kbit/s.
double controlShare(const TransportConfig& c);

/// The budget is total egress, and every slice sample goes to every receiver
/// (one unicast datagram each), so the slice stream itself may use
/// (1 - controlShare) / receivers of it [kbit/s] of samples' serialized
/// payload. Receivers are the configured peers (at least one).
double streamKbps(const TransportConfig& c);

/// The flow controller's period [ms] with one receiver: kFlowPeriodMs, or
/// longer where the stream's payload in it would hold fewer than
/// kSamplesPerPeriod of the largest samples (thin budgets, where a sample is
/// one Ethernet datagram: at 250 kbit/s with four receivers, samples of
/// 1.3 kB and 100 ms, one sample fitted where two did not and the stream ran
/// at half its rate).
int flowBaseMs(const TransportConfig& c);
/// The flow controller's period [ms]: flowBaseMs stretched by the receivers.
/// The stream's bytes of one base period leave per period as samples, each
/// reaching every receiver, so the period stretches with the receivers
/// instead of the bytes per period shrinking (a sample must fit one period's
/// bytes, and the sample size must not depend on the fleet).
int flowPeriodMs(const TransportConfig& c);
/// Bytes the flow controller lets out per period (each message then reaching
/// every receiver): the stream's payload of one base period plus the RTPS
/// headers of the messages that carry it. The controller counts whole
/// messages; counted as payload, the headers (about 120 bytes a full sample)
/// and a period's unused rest had it pass only 86 % of the stream, below what
/// the daemon fed it (MapSender: 85 %), so its queue of new samples never ran
/// dry and repairs, which it serves only then, waited until the whole map had
/// left (10 % loss: a reader stuck 16 s behind one lost sample).
size_t flowBytesPerPeriod(const TransportConfig& c);
/// The flow controller's name (a static string: Fast DDS keeps the pointer).
extern const char* const kFlowControllerName;

/// kbit/s as bytes per second.
double bytesPerSecond(double kbps);

/// Bytes the flow controller may send per period.
size_t bytesPerPeriod(double bandwidth_kbps);

/// The rate every datagram the participant sends is paced to [kbit/s]: a hard
/// cap just under the budget, beneath the flow controller's share for the
/// slice stream (EgressPacer).
double pacedKbps(const TransportConfig& c);

/// The largest slice sample's RTPS message, headers included (one UDP payload).
size_t sampleDatagramBytes(double bandwidth_kbps);

/// Largest slice sample: a fraction of the per-period budget, so that the
/// controller, which sends only whole samples per period, fills each period
/// nearly to the budget; but at thin budgets one full Ethernet datagram, since
/// each datagram pays its headers (docs/protocol.md, "Sample size"); less
/// with security, whose framing each datagram carries too.
size_t maxSampleBytes(double bandwidth_kbps, bool secure);

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
