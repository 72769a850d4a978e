#include "participant.hpp"

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/test_UDPv4TransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>

#include <algorithm>
#include <cmath>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/rtps/flowcontrol/FlowControllerDescriptor.hpp>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include "egress_pacer.hpp"
#include "paced_transport.hpp"

namespace tomomap::transport {

using namespace eprosima::fastdds::dds;
using eprosima::fastrtps::rtps::IPLocator;
using eprosima::fastrtps::rtps::Locator_t;

const char* const kFlowControllerName = "tomomap_budget";

double bytesPerSecond(double kbps) { return kbps * 1000.0 / 8.0; }

size_t bytesPerPeriod(double kbps) {
  return static_cast<size_t>(std::max(1.0, bytesPerSecond(kbps) * kFlowPeriodMs / 1000.0));
}

double pacedKbps(const TransportConfig& c) {
  // A strict pacer lets through at most its rate over any window plus the one
  // datagram that started last: at 250 kbit/s a 1.5 kB datagram is 2.4 kbit/s
  // over 5 s, a 9 kB security handshake 14. 3 % below the budget keeps every
  // 5 s window under it with either.
  constexpr double kBelowBudget = 0.97;
  return kBelowBudget * c.bandwidth_kbps;
}

namespace {
size_t receivers(const TransportConfig& c) { return std::max<size_t>(1, c.peers.size()); }
}  // namespace

double controlShare(const TransportConfig& c) {
  // 13 % with two receivers (peaks 743-770 kbit/s of 800 seen with 10 %), 21 %
  // with four and 29 % with six (with 10 %: peaks up to 921 and 958 kbit/s).
  // Security adds handshakes (about 5 kB each way per peer), secure discovery
  // and a MAC on every heartbeat and acknowledgement: with 13 % for two
  // receivers a peak of 818 kbit/s of 800 was seen.
  constexpr double kBase = 0.05, kPerReceiver = 0.04, kSecure = 0.05, kMax = 0.5;
  return std::min(kMax,
                  kBase + kPerReceiver * static_cast<double>(receivers(c)) + (c.security.enabled() ? kSecure : 0.0));
}

double streamKbps(const TransportConfig& c) {
  return (1 - controlShare(c)) * c.bandwidth_kbps / static_cast<double>(receivers(c));
}

namespace {

/// Datagram bytes besides a sample's CDR that keep the sample one DATA
/// submessage. Fast DDS 2.9 cuts a sample into DATA_FRAGs when its serialized
/// payload (the CDR after a 4-byte encapsulation header) exceeds the message
/// size less 116 bytes it keeps for headers (RTPS header, INFO_DST, INFO_TS,
/// a DATA_FRAG header, a piggybacked HEARTBEAT) and less the 60-byte
/// statistics submessage Debian's build ends every message with. 16 bytes of
/// margin. (A reserve of 160 had every full sample cut in two, 1,452 and 176
/// bytes on the link; 128 plus a 256-byte sample header before left 220 bytes
/// of every full datagram empty.)
constexpr size_t kRtpsOverhead = 116 + 60 + 4 + 16;
/// What DDS Security adds to a sample with metadata_protection_kind ENCRYPT:
/// SEC_PREFIX (24 bytes), SEC_POSTFIX (a 16-byte MAC and its count) and the
/// encrypted body's framing, with a margin.
constexpr size_t kSecurityOverhead = 64;

size_t overhead(bool secure) { return kRtpsOverhead + (secure ? kSecurityOverhead : 0); }

/// The largest datagram DDS Security's handshake needs: its messages carry the
/// certificate and the signed permissions and are never fragmented (with
/// datagrams of 1,472 bytes Fast DDS logged "Cannot serialize
/// ParticipantGenericMessage" and no peer ever authenticated). The rest of a
/// handshake message (participant data, key agreement, signatures, names)
/// took under 2 kB; 4 kB of margin.
size_t handshakeBytes(const SecurityFiles& f) {
  std::error_code ec;
  const auto size = [&](const std::string& path) { return static_cast<size_t>(std::filesystem::file_size(path, ec)); };
  return size(f.certificate) + size(f.permissions) + 4096;
}
/// Participant lease [s]. Announcements go every fifth of it: Fast DDS sends
/// each one twice to every peer (to its initial-peer locator and to the
/// discovered one, the same address here), so every tenth cost 3.6 % of an
/// agent's bytes with four peers at 250 kbit/s; a fifth, 1.8 %. Five rounds
/// of two copies each must all be lost before a live peer is dropped.
constexpr int kLeaseS = 60;

}  // namespace

namespace {

/// The slice stream's bytes written per second (each then reaches every receiver).
double streamBytesPerSecond(const TransportConfig& c) {
  return bytesPerSecond(streamKbps(c) * static_cast<double>(receivers(c)));
}

}  // namespace

/// The largest slice sample's datagram, its RTPS headers included: a
/// kSamplesPerPeriod-th of a period's bytes (one sample per period as at
/// first lost up to half of it). Thin budgets: one Ethernet-sized datagram
/// (each datagram costs its headers; smaller samples paid them more often),
/// and the period grows instead (flowBaseMs). And no sample may exceed one
/// UDP datagram.
size_t sampleDatagramBytes(double kbps) {
  constexpr size_t kDatagram = 60000;
  return std::clamp<size_t>(bytesPerPeriod(kbps) / kSamplesPerPeriod, kUdpPayloadInOneFrame, kDatagram);
}

size_t maxSampleBytes(double kbps, bool secure) { return sampleDatagramBytes(kbps) - overhead(secure); }

int flowBaseMs(const TransportConfig& c) {
  const double sample = static_cast<double>(maxSampleBytes(c.bandwidth_kbps, c.security.enabled()));
  return std::max(kFlowPeriodMs,
                  static_cast<int>(std::ceil(1000.0 * kSamplesPerPeriod * sample / streamBytesPerSecond(c))));
}

int flowPeriodMs(const TransportConfig& c) { return flowBaseMs(c) * static_cast<int>(receivers(c)); }

size_t flowBytesPerPeriod(const TransportConfig& c) {
  // The controller counts whole RTPS messages, headers and all: the stream's
  // payload of a base period, each full sample with its message's headers.
  const double message_per_payload = static_cast<double>(sampleDatagramBytes(c.bandwidth_kbps)) /
                                     static_cast<double>(maxSampleBytes(c.bandwidth_kbps, c.security.enabled()));
  return static_cast<size_t>(streamBytesPerSecond(c) * flowBaseMs(c) / 1000.0 * message_per_payload);
}

namespace {

Locator_t udp(const std::string& host, uint16_t port) {
  Locator_t l;
  l.kind = LOCATOR_KIND_UDPv4;
  if (!IPLocator::setIPv4(l, host)) throw std::runtime_error("'" + host + "' is not an IPv4 address");
  l.port = port;
  return l;
}

/// DDS Security's built-in plugins from the files: PKI-DH authentication,
/// permissions checked against the signed documents, AES-GCM-GMAC crypto.
void addSecurity(const SecurityFiles& f, DomainParticipantQos& q) {
  auto& props = q.properties().properties();
  auto add = [&](const std::string& name, const std::string& value) { props.emplace_back(name, value); };
  auto file = [](const std::string& path) { return "file://" + path; };
  const std::string auth = "dds.sec.auth.builtin.PKI-DH.", access = "dds.sec.access.builtin.Access-Permissions.";
  add("dds.sec.auth.plugin", "builtin.PKI-DH");
  add(auth + "identity_ca", file(f.ca));
  add(auth + "identity_certificate", file(f.certificate));
  add(auth + "private_key", file(f.private_key));
  if (!f.crl.empty()) add(auth + "identity_crl", file(f.crl));
  add("dds.sec.access.plugin", "builtin.Access-Permissions");
  add(access + "permissions_ca", file(f.ca));
  add(access + "governance", file(f.governance));
  add(access + "permissions", file(f.permissions));
  add("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
}

}  // namespace

DomainParticipant* createParticipant(const TransportConfig& c, std::shared_ptr<EgressPacer> pacer,
                                     DomainParticipantListener* listener) {
  DomainParticipantQos q;
  q.name(participantName(c.agent));
  if (c.security.enabled()) addSecurity(c.security, q);
  q.transport().use_builtin_transports = false;
  std::shared_ptr<eprosima::fastdds::rtps::SocketTransportDescriptor> transport;
  if (c.test_drop_percent > 0) {
    // Test only: Fast DDS's own lossy UDPv4 transport drops this share of every
    // RTPS message this participant sends (the kernel here has no netem).
    auto lossy = std::make_shared<eprosima::fastdds::rtps::test_UDPv4TransportDescriptor>();
    lossy->percentageOfMessagesToDrop = static_cast<uint8_t>(c.test_drop_percent);
    transport = lossy;
  } else {
    transport = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  }
  transport->sendBufferSize = 1 << 20;
  transport->receiveBufferSize = 1 << 20;
  // RTPS packs several samples into one datagram up to this size (64 kB by
  // default), which IP then cuts into MTU-sized fragments: on a lossy link one
  // lost fragment loses every sample in the datagram. One sample per datagram,
  // and no datagram above an Ethernet MTU where the samples are that small;
  // except with security, whose handshake needs larger ones.
  size_t datagram = sampleDatagramBytes(c.bandwidth_kbps);
  if (c.security.enabled()) datagram = std::max(datagram, handshakeBytes(c.security));
  transport->maxMessageSize = static_cast<uint32_t>(datagram);
  q.transport().user_transports.push_back(
      std::make_shared<PacedTransportDescriptor>(transport, std::move(pacer), /*own_sender=*/c.test_drop_percent == 0));

  auto& builtin = q.wire_protocol().builtin;
  builtin.metatrafficUnicastLocatorList.push_back(udp(c.address, c.discovery_port));
  q.wire_protocol().default_unicast_locator_list.push_back(udp(c.address, c.data_port));
  for (const auto& p : c.peers) builtin.initialPeersList.push_back(udp(p.host, p.port));
  // A peer is dropped after this long without a word. Long enough to ride out
  // a radio dropout: a dropped peer that comes back matches anew and gets our
  // whole map from the durable history again, while a kept one gets repairs
  // of just what was lost. Claims do not wait for it (claim_timeout_s).
  builtin.discovery_config.leaseDuration = eprosima::fastrtps::Duration_t(kLeaseS, 0);
  builtin.discovery_config.leaseDuration_announcementperiod = eprosima::fastrtps::Duration_t(kLeaseS / 5, 0);
  // Three announcements at the start (the first plus `count`; Fast DDS's
  // default makes six), each to every peer:
  // peers that start later announce themselves and are answered, so the
  // rest reached no one new (seven agents at 800 kbit/s: 26 announcements
  // to each peer in 48 s, 3.4 % of an agent's bytes).
  builtin.discovery_config.initial_announcements.count = 2;

  auto flow = std::make_shared<eprosima::fastdds::rtps::FlowControllerDescriptor>();
  flow->name = kFlowControllerName;
  flow->scheduler = eprosima::fastdds::rtps::FlowControllerSchedulerPolicy::FIFO;
  // Per stretched period, the stream's share for every receiver: each byte
  // written leaves once per receiver, so the egress stays within the budget.
  flow->max_bytes_per_period = static_cast<int32_t>(flowBytesPerPeriod(c));
  flow->period_ms = static_cast<uint64_t>(flowPeriodMs(c));
  q.flow_controllers().push_back(flow);

  DomainParticipant* p = DomainParticipantFactory::get_instance()->create_participant(static_cast<DomainId_t>(c.domain),
                                                                                      q, listener, StatusMask::none());
  if (!p && c.security.enabled())
    throw std::runtime_error(
        "cannot create the secure DDS participant: check that the [security] files belong together (the "
        "certificate and permissions signed by `ca`, the key matching the certificate, none expired), or ports " +
        std::to_string(c.discovery_port) + "/" + std::to_string(c.data_port) + " on " + c.address + " in use");
  if (!p)
    throw std::runtime_error("cannot create the DDS participant (ports " + std::to_string(c.discovery_port) + "/" +
                             std::to_string(c.data_port) + " on " + c.address + " in use?)");
  return p;
}

}  // namespace tomomap::transport
