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

namespace {

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
