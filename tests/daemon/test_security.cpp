// Who may speak for an agent. Real daemons, and an intruder that is a real
// Fast DDS participant in this test process, forging estimates on the wire.
#include <gtest/gtest.h>

#include <atomic>

#include "fleet.hpp"
#include "fleet/fleet_keys.hpp"
#include "transport/bus.hpp"
#include "transport/estimate_wire.hpp"

using namespace tomomap;
using namespace tomomap::test;
using namespace std::chrono_literals;

namespace {

/// A participant of our own making that joins the fleet's peers as `name`.
struct Intruder {
  std::atomic<int> peers_up{0};
  std::unique_ptr<transport::Bus> bus;

  Intruder(const std::string& name, uint16_t port, const std::vector<transport::PeerAddress>& fleet,
           const transport::SecurityFiles& files = {}) {
    transport::TransportConfig c;
    c.agent = name;
    c.discovery_port = port;
    c.data_port = static_cast<uint16_t>(port + 1);
    c.peers = fleet;
    c.security = files;
    transport::BusHandlers h;
    h.peer = [this](const std::string&, bool alive) { peers_up += alive ? 1 : 0; };
    bus = std::make_unique<transport::Bus>(c, h);
  }

  /// Publishes `real` moved by 11 m in x, in the name of `computed_by`.
  void forge(const nlohmann::json& real, const std::string& computed_by) {
    AgreedTransform t = agreedFromJson(real);
    t.T_target_source.x += 11;
    t.computed_by = computed_by;
    bus->publish(transport::toWire(t));
  }
};

transport::SecurityFiles robotFiles(const std::string& dir) {
  using F = fleet::RobotFiles;
  return {dir + "/" + F::ca, dir + "/" + F::certificate, dir + "/" + F::private_key, dir + "/" + F::governance,
          dir + "/" + F::permissions, ""};
}

size_t statusCount(const Fleet& fleet, const std::string& id, const std::string& key) {
  return fleet.readJson(id, "status.json").value(key, size_t{0});
}

}  // namespace

TEST(Identity, AnEstimateInAnotherAgentsNameIsDroppedAndCounted) {
  TempDir dir;
  ASSERT_EQ(runTomomap("synth -o " + (dir / "world") + " -n 2 --noise low -s 3 --scale 0.5").exit_code, 0);
  Fleet fleet(dir);
  const std::vector<AgentSpec> agents{{"alpha", dir / "world/map_0.pcd"}, {"bravo", dir / "world/map_1.pcd"}};
  for (const auto& a : agents) fleet.start(a, agents);
  ASSERT_TRUE(fleet.waitForTransforms({"alpha", "bravo"}, 1, 120s)) << fleet.log("bravo");
  const auto real = fleet.transforms("bravo").at("alpha<-bravo");

  // Without security a participant's name is its word: mallory says who she
  // is, then signs an estimate with alpha's name (the versions are public).
  Intruder mallory("mallory", fleet.port(10), {{"alpha", "127.0.0.1", fleet.port(0)}, {"bravo", "127.0.0.1", fleet.port(1)}});
  mallory.forge(real, "alpha");
  EXPECT_TRUE(Fleet::waitFor([&] { return statusCount(fleet, "bravo", "dropped_impostor_samples") > 0; }, 60s))
      << fleet.readJson("bravo", "status.json").dump(2);
  EXPECT_TRUE(Fleet::waitFor([&] { return statusCount(fleet, "alpha", "dropped_impostor_samples") > 0; }, 60s));
  for (const std::string id : {"alpha", "bravo"}) {
    const auto kept = fleet.transforms(id).at("alpha<-bravo");
    EXPECT_EQ(kept["T_target_source"]["x"], real["T_target_source"]["x"]) << id << " kept the true transform";
    EXPECT_EQ(kept["computed_by"], real["computed_by"]);
  }
  EXPECT_NE(fleet.log("bravo").find("in the name of 'alpha'"), std::string::npos) << fleet.log("bravo");
}

TEST(Security, ASecureFleetAgreesAndNeitherStrangersNorLiarsChangeIt) {
  TempDir dir;
  ASSERT_EQ(runTomomap("synth -o " + (dir / "world") + " -n 2 --noise low -s 3 --scale 0.5").exit_code, 0);
  const auto keys = runTomomap("fleet-keys --agents alpha,bravo,charlie -o " + (dir / "keys"));
  ASSERT_EQ(keys.exit_code, 0) << keys.output;
  ASSERT_EQ(runTomomap("fleet-keys --agents alpha -o " + (dir / "other-fleet")).exit_code, 0);
  Fleet fleet(dir);
  std::vector<AgentSpec> agents{{"alpha", dir / "world/map_0.pcd"}, {"bravo", dir / "world/map_1.pcd"}};
  for (auto& a : agents) a.extra = fleet::securityConfig(dir / ("keys/" + a.id), false);
  for (const auto& a : agents) fleet.start(a, agents);
  ASSERT_TRUE(fleet.waitForTransforms({"alpha", "bravo"}, 1, 120s)) << fleet.log("alpha") << fleet.log("bravo");
  EXPECT_TRUE(fleet.readJson("bravo", "status.json").value("secure", false));
  const auto real = fleet.transforms("bravo").at("alpha<-bravo");
  const std::vector<transport::PeerAddress> peers{{"alpha", "127.0.0.1", fleet.port(0)},
                                                  {"bravo", "127.0.0.1", fleet.port(1)}};

  // A stranger: a valid certificate named alpha, from another CA. Then a
  // liar: charlie's real keys, calling itself alpha. Then charlie as itself,
  // writing an estimate in alpha's name. Each forges the transform.
  Intruder stranger("alpha", fleet.port(10), peers, robotFiles(dir / "other-fleet/alpha"));
  stranger.forge(real, "alpha");
  Intruder liar("alpha", fleet.port(12), peers, robotFiles(dir / "keys/charlie"));
  liar.forge(real, "alpha");
  Intruder charlie("charlie", fleet.port(14), peers, robotFiles(dir / "keys/charlie"));
  charlie.forge(real, "alpha");

  EXPECT_TRUE(Fleet::waitFor([&] { return charlie.peers_up >= 2; }, 60s)) << "charlie authenticates";
  for (const std::string id : {"alpha", "bravo"}) {
    EXPECT_TRUE(Fleet::waitFor([&] { return statusCount(fleet, id, "refused_participants") > 0; }, 60s))
        << id << " refuses the participant of charlie that names itself alpha\n" << fleet.log(id);
    EXPECT_TRUE(Fleet::waitFor([&] { return statusCount(fleet, id, "dropped_impostor_samples") > 0; }, 60s))
        << id << " drops charlie's estimate in alpha's name\n" << fleet.log(id);
  }
  EXPECT_NE(fleet.log("bravo").find("authenticated as charlie"), std::string::npos) << fleet.log("bravo");
  // The stranger started first and had as long as the others: it never got in.
  EXPECT_EQ(stranger.peers_up, 0) << "a certificate from another CA does not authenticate";
  for (const std::string id : {"alpha", "bravo"}) {
    const auto kept = fleet.transforms(id).at("alpha<-bravo");
    EXPECT_EQ(kept["T_target_source"]["x"], real["T_target_source"]["x"]) << id << " kept the true transform";
    EXPECT_EQ(kept["computed_by"], real["computed_by"]);
  }
}
