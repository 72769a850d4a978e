#include "fleet_keys.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "documents.hpp"
#include "pki.hpp"

namespace tomomap::fleet {
namespace {

namespace fs = std::filesystem;

constexpr const char* kCaKey = "ca.key";         ///< the CA's private key: never leaves the operator
constexpr const char* kRevoked = "revoked.txt";  ///< serials revoked so far, one per line
constexpr const char* kCaName = "tomomap fleet CA";

std::string utc(std::time_t t) {
  std::tm tm{};
  gmtime_r(&t, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &tm);
  return text;
}

class Writer {
 public:
  explicit Writer(FleetResult& r) : result_(r) {}
  void operator()(const fs::path& path, const std::string& text, bool secret = false) {
    // A secret is created unreadable to others before anything is in it.
    const fs::path tmp = path.string() + ".tmp";
    {
      std::ofstream f(tmp, std::ios::trunc);
      if (!f) throw std::runtime_error("cannot write " + tmp.string());
      if (secret) fs::permissions(tmp, fs::perms::owner_read | fs::perms::owner_write);
      f << text;
      if (!f.flush()) throw std::runtime_error("cannot write " + tmp.string());
    }
    fs::rename(tmp, path);
    result_.written.push_back(path.string());
  }

 private:
  FleetResult& result_;
};

std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

}  // namespace

FleetResult makeFleet(const FleetRequest& r) {
  if (r.days < 1 || r.ca_days < 1) throw std::runtime_error("validity must be at least one day");
  FleetResult result;
  Writer write(result);
  const fs::path out(r.out);
  fs::create_directories(out);

  const bool have_key = fs::exists(out / kCaKey), have_cert = fs::exists(out / RobotFiles::ca);
  if (have_key != have_cert)
    throw std::runtime_error(out.string() + ": has " + (have_key ? kCaKey : RobotFiles::ca) + " but not " +
                             (have_key ? RobotFiles::ca : kCaKey) + "; restore it or start a new fleet folder");
  Key ca_key = have_key ? readKey((out / kCaKey).string()) : newKey();
  Cert ca = have_cert ? readCert((out / RobotFiles::ca).string()) : newCa(ca_key, kCaName, kOrganisation, r.ca_days);
  if (!have_key) {
    write(out / kCaKey, pem(ca_key), /*secret=*/true);
    write(out / RobotFiles::ca, pem(ca));
    result.new_ca = true;
  }
  const std::string governance = smimeSign(governanceXml(), ca, ca_key);
  write(out / RobotFiles::governance, governance);

  for (const auto& agent : r.agents) {
    const fs::path dir = out / agent;
    if (fs::exists(dir / RobotFiles::certificate) && !r.replace)
      throw std::runtime_error(agent + " has keys in " + dir.string() +
                               " already; --replace issues new ones (revoke the old ones with --revoke first)");
    fs::create_directories(dir);
    Key key = newKey();
    Cert cert = issue(key, agent, kOrganisation, ca, ca_key, r.days);
    const std::time_t now = std::time(nullptr);
    const std::string permissions =
        permissionsXml(agent, subject(cert), utc(now - 3600), utc(now + static_cast<std::time_t>(r.days) * 86400));
    write(dir / RobotFiles::private_key, pem(key), /*secret=*/true);
    write(dir / RobotFiles::certificate, pem(cert));
    write(dir / RobotFiles::permissions, smimeSign(permissions, ca, ca_key));
    write(dir / RobotFiles::ca, pem(ca));
    write(dir / RobotFiles::governance, governance);
  }

  if (!r.revoke.empty() || fs::exists(out / kRevoked)) {
    std::set<std::string> serials;
    std::istringstream known(slurp(out / kRevoked));
    for (std::string line; std::getline(known, line);)
      if (!line.empty()) serials.insert(line);
    for (const auto& agent : r.revoke) {
      const fs::path cert = out / agent / RobotFiles::certificate;
      if (!fs::exists(cert)) throw std::runtime_error("cannot revoke " + agent + ": no " + cert.string());
      serials.insert(serialHex(readCert(cert.string())));
    }
    std::string list;
    for (const auto& s : serials) list += s + "\n";
    write(out / kRevoked, list);
    const std::string revocations = crl({serials.begin(), serials.end()}, ca, ca_key, r.ca_days);
    write(out / RobotFiles::crl, revocations);
    // Every robot needs the list; a revoked robot's folder is the one not to deploy.
    for (const auto& entry : fs::directory_iterator(out))
      if (entry.is_directory() && fs::exists(entry.path() / RobotFiles::certificate))
        write(entry.path() / RobotFiles::crl, revocations);
  }
  return result;
}

std::string securityConfig(const std::string& dir, bool with_crl) {
  const std::string d = dir.empty() || dir.back() == '/' ? dir : dir + "/";
  std::string s = "[security]\n";
  s += "ca = \"" + d + RobotFiles::ca + "\"\n";
  s += "certificate = \"" + d + RobotFiles::certificate + "\"\n";
  s += "private_key = \"" + d + RobotFiles::private_key + "\"\n";
  s += "governance = \"" + d + RobotFiles::governance + "\"\n";
  s += "permissions = \"" + d + RobotFiles::permissions + "\"\n";
  if (with_crl) s += "crl = \"" + d + RobotFiles::crl + "\"\n";
  return s;
}

}  // namespace tomomap::fleet
