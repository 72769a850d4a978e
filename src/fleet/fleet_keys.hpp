#pragma once
// A fleet's keys and signed documents in one folder: the CA (kept by the
// operator), and per robot a folder to copy onto it as it is. Running it again
// adds robots, replaces a robot's key or revokes robots with the same CA.
#include <string>
#include <vector>

namespace tomomap::fleet {

struct FleetRequest {
  std::vector<std::string> agents;  ///< robots to issue keys for
  std::vector<std::string> revoke;  ///< robots whose certificates are revoked
  std::string out;                  ///< the fleet folder
  int days = 365;                   ///< validity of robots' certificates and permissions
  int ca_days = 3650;               ///< validity of a new CA
  bool replace = false;             ///< issue new keys for robots that have some
};

struct FleetResult {
  std::vector<std::string> written;  ///< files written, in order
  bool new_ca = false;
};

/// Files in each robot's folder, as the config's [security] keys name them.
struct RobotFiles {
  static constexpr const char* ca = "ca.pem";
  static constexpr const char* certificate = "cert.pem";
  static constexpr const char* private_key = "key.pem";
  static constexpr const char* governance = "governance.p7s";
  static constexpr const char* permissions = "permissions.p7s";
  static constexpr const char* crl = "crl.pem";
};

/// The organisation in every subject: "CN=<agent>,O=tomomap fleet".
inline constexpr const char* kOrganisation = "tomomap fleet";

/// Creates or extends the fleet in `r.out`; throws std::runtime_error (a
/// robot that has keys already without `replace`, an unknown robot to revoke,
/// a CA half there, a file that cannot be written).
FleetResult makeFleet(const FleetRequest& r);

/// The [security] table for a robot's config, its paths relative to `dir`.
std::string securityConfig(const std::string& dir, bool with_crl);

}  // namespace tomomap::fleet
