#pragma once
// What the transport is told by the daemon's config: the agent, its address
// and ports, its peers, its bandwidth budget and its DDS Security files.
#include <cstdint>
#include <string>
#include <vector>

namespace tomomap::transport {

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

}  // namespace tomomap::transport
