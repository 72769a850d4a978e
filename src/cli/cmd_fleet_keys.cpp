// `tomomap fleet-keys`: a fleet's certificates and signed DDS Security
// documents, made with OpenSSL (docs/operations.md, "A secure fleet").
#include <iostream>
#include <memory>
#include <regex>
#include <stdexcept>

#include "commands.hpp"
#include "core/types.hpp"
#include "exit_codes.hpp"
#include "fleet/fleet_keys.hpp"

namespace tomomap::cli {
namespace {

int runFleetKeys(fleet::FleetRequest r) {
  for (const auto& list : {r.agents, r.revoke})
    for (const auto& a : list)
      if (!std::regex_match(a, std::regex("[A-Za-z0-9_-]{1,32}")))
        throw InputError("agent id '" + a + "' must be 1 to 32 letters, digits, '-' or '_' (as in the config)");
  if (r.agents.empty() && r.revoke.empty()) throw InputError("nothing to do: give --agents and/or --revoke");
  fleet::FleetResult done;
  try {
    done = fleet::makeFleet(r);
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
  for (const auto& f : done.written) std::cout << "wrote " << f << "\n";
  if (done.new_ca)
    std::cout << "\nNew fleet CA in " << r.out << ": keep ca.key on this machine only; it signs every robot's keys.\n";
  if (!r.agents.empty()) {
    std::cout
        << "\nCopy " << r.out << "/<agent>/ onto each robot (e.g. to /etc/tomomap/keys/) and add to its config:\n\n"
        << fleet::securityConfig("/etc/tomomap/keys", !r.revoke.empty())
        << "\n(under systemd the service reads key.pem as a credential: docs/operations.md, \"A secure fleet\")\n";
  }
  if (!r.revoke.empty())
    std::cout << "\nRevoked " << r.revoke.size() << " robot(s): deploy crl.pem to every other robot, set `crl` in "
              << "[security] and reload (systemctl reload tomomapd).\n";
  return kExitOk;
}

}  // namespace

Command addFleetKeysCommand(CLI::App& app) {
  auto r = std::make_shared<fleet::FleetRequest>();
  CLI::App* sub = app.add_subcommand(
      "fleet-keys",
      "Create or extend a secure fleet: a CA, and per robot a P-256 key, a certificate (CN=<agent>) and signed DDS "
      "Security governance and permissions, in one folder per robot. Run again to add robots, replace a robot's "
      "keys or revoke robots.\nExit codes: 0 done, 2 bad arguments or files.");
  sub->add_option("--agents", r->agents, "robots to issue keys for (comma-separated agent ids)")->delimiter(',');
  sub->add_option("--revoke", r->revoke, "robots whose certificates to revoke (writes crl.pem)")->delimiter(',');
  sub->add_option("-o,--out", r->out, "the fleet folder (holds the CA; created if missing)")->required();
  sub->add_option("--days", r->days, "validity of the robots' certificates and permissions [days]")
      ->capture_default_str()
      ->check(CLI::Range(1, 36500));
  sub->add_option("--ca-days", r->ca_days, "validity of a new CA and of the revocation list [days]")
      ->capture_default_str()
      ->check(CLI::Range(1, 36500));
  sub->add_flag("--replace", r->replace, "issue new keys for robots that have some (rotation)");
  return {sub, [r] { return runFleetKeys(*r); }};
}

}  // namespace tomomap::cli
