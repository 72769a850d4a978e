// The fleet's PKI: what fleet-keys writes verifies as DDS Security will check
// it, a tampered document or a foreign CA does not, and revocation revokes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "fleet/fleet_keys.hpp"
#include "fleet/pki.hpp"
#include "support.hpp"

using namespace tomomap::fleet;
using tomomap::test::readText;
using tomomap::test::TempDir;
namespace fs = std::filesystem;

namespace {

FleetRequest request(const std::string& out, std::vector<std::string> agents) {
  FleetRequest r;
  r.out = out;
  r.agents = std::move(agents);
  return r;
}

}  // namespace

TEST(FleetKeys, EveryRobotsFilesVerifyAgainstTheFleetCa) {
  TempDir dir;
  const std::string out = dir / "fleet";
  const FleetResult done = makeFleet(request(out, {"alpha", "bravo"}));
  EXPECT_TRUE(done.new_ca);
  const Cert ca = readCert(out + "/ca.pem");
  for (const std::string agent : {"alpha", "bravo"}) {
    const fs::path d = fs::path(out) / agent;
    const Cert cert = readCert((d / RobotFiles::certificate).string());
    std::string why;
    EXPECT_TRUE(verify(cert, ca, "", why)) << why;
    EXPECT_EQ(subject(cert), "CN=" + agent + ",O=tomomap fleet");
    const std::string grant = smimeVerify(readText(d / RobotFiles::permissions), ca);
    EXPECT_NE(grant.find("<subject_name>CN=" + agent + ",O=tomomap fleet</subject_name>"), std::string::npos) << grant;
    EXPECT_NE(grant.find("<topic>tomomap/*</topic>"), std::string::npos);
    EXPECT_NE(smimeVerify(readText(d / RobotFiles::governance), ca).find("<enable_join_access_control>true"),
              std::string::npos);
    EXPECT_EQ(readText(d / RobotFiles::ca), readText(fs::path(out) / "ca.pem")) << "each robot's folder is complete";
    const auto perms = fs::status(d / RobotFiles::private_key).permissions();
    EXPECT_EQ(perms & (fs::perms::group_all | fs::perms::others_all), fs::perms::none) << "keys are private";
    readKey((d / RobotFiles::private_key).string());  // parses
  }
}

TEST(FleetKeys, ATamperedDocumentOrAForeignCaDoesNotVerify) {
  TempDir dir;
  makeFleet(request(dir / "ours", {"alpha"}));
  makeFleet(request(dir / "theirs", {"alpha"}));
  const Cert ours = readCert(dir / "ours/ca.pem"), theirs = readCert(dir / "theirs/ca.pem");
  std::string permissions = readText(dir / "ours/alpha/permissions.p7s");
  EXPECT_THROW(smimeVerify(permissions, theirs), std::runtime_error);
  const size_t at = permissions.find("<topic>tomomap/*</topic>");
  ASSERT_NE(at, std::string::npos);
  permissions.replace(at, 24, "<topic>*</topic>        ");  // widen the grant
  EXPECT_THROW(smimeVerify(permissions, ours), std::runtime_error);
  std::string why;
  EXPECT_FALSE(verify(readCert(dir / "theirs/alpha/cert.pem"), ours, "", why));
  EXPECT_FALSE(why.empty());
}

TEST(FleetKeys, AddingRobotsKeepsTheCaAndReplacingNeedsToBeAskedFor) {
  TempDir dir;
  const std::string out = dir / "fleet";
  makeFleet(request(out, {"alpha"}));
  const std::string ca = readText(fs::path(out) / "ca.pem");
  const FleetResult more = makeFleet(request(out, {"bravo"}));
  EXPECT_FALSE(more.new_ca);
  EXPECT_EQ(readText(fs::path(out) / "ca.pem"), ca);
  std::string why;
  EXPECT_TRUE(verify(readCert(out + "/bravo/cert.pem"), readCert(out + "/ca.pem"), "", why)) << why;
  EXPECT_THROW(makeFleet(request(out, {"alpha"})), std::runtime_error) << "alpha has keys already";
  const std::string old_cert = readText(fs::path(out) / "alpha/cert.pem");
  FleetRequest rotate = request(out, {"alpha"});
  rotate.replace = true;
  makeFleet(rotate);
  EXPECT_NE(readText(fs::path(out) / "alpha/cert.pem"), old_cert);
}

TEST(FleetKeys, ARevokedRobotsCertificateFailsAgainstTheListOthersPass) {
  TempDir dir;
  const std::string out = dir / "fleet";
  makeFleet(request(out, {"alpha", "bravo"}));
  FleetRequest revoke;
  revoke.out = out;
  revoke.revoke = {"bravo"};
  makeFleet(revoke);
  const Cert ca = readCert(out + "/ca.pem");
  const std::string list = readText(fs::path(out) / RobotFiles::crl);
  EXPECT_EQ(readText(fs::path(out) / "alpha" / RobotFiles::crl), list) << "every robot's folder gets the list";
  std::string why;
  EXPECT_TRUE(verify(readCert(out + "/alpha/cert.pem"), ca, list, why)) << why;
  EXPECT_FALSE(verify(readCert(out + "/bravo/cert.pem"), ca, list, why));
  EXPECT_NE(why.find("revoked"), std::string::npos) << why;
  FleetRequest unknown = revoke;
  unknown.revoke = {"zulu"};
  EXPECT_THROW(makeFleet(unknown), std::runtime_error);
}
