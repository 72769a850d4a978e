// tomomapd's config file: defaults, errors with file, line and key.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>

#include "config.hpp"
#include "core/match_settings.hpp"
#include "fleet/fleet_keys.hpp"
#include "settings.hpp"
#include "support.hpp"

using namespace tomomap;
using namespace tomomap::daemon;
using tomomap::test::TempDir;

namespace {

std::string errorOf(TempDir& dir, const std::string& text) {
  std::ofstream(dir / "c.toml") << text;
  try {
    loadConfig(dir / "c.toml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(DaemonConfig, MinimalConfigGetsDefaults) {
  TempDir dir;
  std::ofstream(dir / "c.toml") << "agent = \"alpha\"\nmap = \"maps/a.pcd\"\ndiscovery_port = 17500\n"
                                << "[[peer]]\nid = \"bravo\"\nhost = \"10.0.0.2\"\nport = 17500\n";
  const Config c = loadConfig(dir / "c.toml");
  EXPECT_EQ(c.agent(), "alpha");
  EXPECT_EQ(c.map, dir / "maps/a.pcd");  // relative to the config file
  EXPECT_EQ(c.transport.data_port, 17501);
  EXPECT_DOUBLE_EQ(c.match.grid, MatchParams{}.grid);
  EXPECT_EQ(c.match.min_support, MatchParams{}.min_support);
  EXPECT_DOUBLE_EQ(c.transport.bandwidth_kbps, 10000);
  ASSERT_EQ(c.transport.peers.size(), 1u);
  EXPECT_TRUE(c.isPeer("bravo"));
  EXPECT_FALSE(c.isPeer("mallory"));
}

TEST(DaemonConfig, ErrorsNameFileLineAndKey) {
  TempDir dir;
  std::string e = errorOf(dir, "agent = \"alpha\"\nmap = \"a.pcd\"\ndiscovery_port = 80\n");
  EXPECT_NE(e.find("c.toml:3:"), std::string::npos) << e;
  EXPECT_NE(e.find("'discovery_port'"), std::string::npos) << e;
  e = errorOf(dir, "agent = \"alpha\"\nmap = \"a.pcd\"\ndiscovery_port = 17500\ncolour = 3\n");
  EXPECT_NE(e.find("c.toml:4:"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown key"), std::string::npos) << e;
  e = errorOf(dir,
              "agent = \"alpha\"\nmap = \"a.pcd\"\ndiscovery_port = 17500\n[[peer]]\nid = \"b\"\nhost = "
              "\"nowhere\"\nport = 1\n");
  EXPECT_NE(e.find("c.toml:6:"), std::string::npos) << e;
  EXPECT_NE(e.find("IPv4"), std::string::npos) << e;
  e = errorOf(dir,
              "agent = \"alpha\"\nmap = \"a.pcd\"\ndiscovery_port = 17500\n[[peer]]\nid = \"alpha\"\nhost = "
              "\"1.2.3.4\"\nport = 17600\n");
  EXPECT_NE(e.find("own id"), std::string::npos) << e;
  e = errorOf(dir, "agent = \"alpha\"\nmap = [1\n");
  EXPECT_NE(e.find("c.toml:2:"), std::string::npos) << e;
  e = errorOf(dir, "map = \"a.pcd\"\ndiscovery_port = 17500\n");
  EXPECT_NE(e.find("'agent' is required"), std::string::npos) << e;
}

TEST(DaemonConfig, TheMatchTableOverridesTheMatchersDefaults) {
  TempDir dir;
  const std::string base = "agent = \"alpha\"\nmap = \"a.pcd\"\ndiscovery_port = 17500\ngrid = 0.1\n";
  std::ofstream(dir / "c.toml") << base << "[match]\nmin_support = 5\nconsensus_yaw_deg = 5\nthreads = 1\n"
                                << "max_features = 500\n";
  const Config c = loadConfig(dir / "c.toml");
  EXPECT_DOUBLE_EQ(c.match.grid, 0.1);
  EXPECT_EQ(c.match.min_support, 5);
  EXPECT_NEAR(c.match.consensus_yaw, radians(5), 1e-12);
  EXPECT_EQ(c.match.threads, 1);
  EXPECT_EQ(c.match.features.max_features, 500);
  EXPECT_EQ(c.match.min_matches, MatchParams{}.min_matches) << "keys not given keep the default";
  EXPECT_NE(describe(c).find("match.min_support = 5"), std::string::npos) << describe(c);

  std::string e = errorOf(dir, base + "[match]\nmin_support = 2.5\n");
  EXPECT_NE(e.find("c.toml:6:"), std::string::npos) << e;
  EXPECT_NE(e.find("'match.min_support': must be a whole number"), std::string::npos) << e;
  e = errorOf(dir, base + "[match]\nransac = 3\n");
  EXPECT_NE(e.find("'match.ransac': unknown key"), std::string::npos) << e;
  e = errorOf(dir, base + "match = 3\n");
  EXPECT_NE(e.find("must be a table"), std::string::npos) << e;
}

TEST(DaemonConfig, AMapsKnownUpIsThreeNumbersAndLeavesTheEstimateAlone) {
  TempDir dir;
  const std::string base = "agent = \"alpha\"\nmap = \"a.pcd\"\ndiscovery_port = 17500\n";
  std::ofstream(dir / "c.toml") << base << "map_up = \"0.05, -0.02, 1\"\n";
  const Config c = loadConfig(dir / "c.toml");
  ASSERT_TRUE(c.map_up);
  EXPECT_TRUE(c.map_up->isApprox(Eigen::Vector3d(0.05, -0.02, 1.0)));
  EXPECT_NE(describe(c).find("map_up = 0.05, -0.02, 1"), std::string::npos) << describe(c);
  std::ofstream(dir / "c.toml") << base;
  EXPECT_FALSE(loadConfig(dir / "c.toml").map_up) << "estimated unless given";
  EXPECT_TRUE(MatchParams{}.level && loadConfig(dir / "c.toml").match.level) << "a leaning map is levelled";
  for (const char* bad : {"\"0, 0, 0\"", "\"1, 2\"", "\"up\"", "\"1, 2, 3, 4\"", "\"nan, 0, 1\""}) {
    const std::string e = errorOf(dir, base + "map_up = " + bad + "\n");
    EXPECT_NE(e.find("c.toml:4:"), std::string::npos) << bad << ": " << e;
    EXPECT_NE(e.find("'map_up': must be a non-zero direction"), std::string::npos) << bad << ": " << e;
  }
  const std::string side = errorOf(dir, base + "map_up = \"0, 1, 0\"\n");
  EXPECT_NE(side.find("'map_up': leans 90.0 deg from z: a map is levelled by at most 45 deg"), std::string::npos)
      << side << ": peers would refuse every announcement of it";
}

TEST(DaemonConfig, AWorldFrameIsOneFrameId) {
  TempDir dir;
  const std::string base = "agent = \"alpha\"\nmap = \"a.pcd\"\ndiscovery_port = 17500\n[ros2]\n";
  std::ofstream(dir / "c.toml") << base << "world = \"world\"\n";
  EXPECT_EQ(loadConfig(dir / "c.toml").ros2.world, "world");
  std::ofstream(dir / "c.toml") << base;
  EXPECT_EQ(loadConfig(dir / "c.toml").ros2.world, "") << "none unless asked: the root's map is the tree's root";
  const std::string e = errorOf(dir, base + "world = \"{agent}/world\"\n");
  EXPECT_NE(e.find("c.toml:5:"), std::string::npos) << e;
  EXPECT_NE(e.find("'ros2.world': must be one frame id"), std::string::npos) << e;
  const std::string own = errorOf(dir, base + "world = \"alpha/map\"\n");
  EXPECT_NE(own.find("'ros2.world': 'alpha/map' is alpha's map frame"), std::string::npos) << own;
}

TEST(DaemonConfig, TheRos2TableTurnsTfStaticOnWithFramesAndARootFromTheFleet) {
  TempDir dir;
  const std::string base = "agent = \"bravo\"\nmap = \"a.pcd\"\ndiscovery_port = 17500\n";
  const std::string peers = "[[peer]]\nid = \"alpha\"\nhost = \"1.2.3.4\"\nport = 17600\n";
  std::ofstream(dir / "c.toml") << base << peers;
  const Config off = loadConfig(dir / "c.toml");
  EXPECT_FALSE(off.ros2.enabled) << "no table, no ROS 2";
  std::ofstream(dir / "c.toml") << base << peers << "[ros2]\ndomain = 7\n";
  const Config on = loadConfig(dir / "c.toml");
  EXPECT_TRUE(on.ros2.enabled);
  EXPECT_EQ(on.ros2.domain, 7);
  EXPECT_TRUE(on.ros2.localhost_only);
  EXPECT_EQ(on.treeRoot(), "alpha") << "the lowest id of the fleet";
  EXPECT_EQ(on.ros2.frameOf("bravo"), "bravo/map");
  EXPECT_NE(describe(on).find("ros2.root = alpha"), std::string::npos) << describe(on);

  std::string e = errorOf(dir, base + peers + "[ros2]\nroot = \"zulu\"\n");
  EXPECT_NE(e.find("'ros2.root': 'zulu' is neither this agent nor one of its peers"), std::string::npos) << e;
  e = errorOf(dir, base + peers + "[ros2]\nframe = \"map\"\n");
  EXPECT_NE(e.find("c.toml:9:"), std::string::npos) << e;
  EXPECT_NE(e.find("must contain {agent}"), std::string::npos) << e;
  e = errorOf(dir, base + "[ros2]\nenabled = \"yes\"\n");
  EXPECT_NE(e.find("'ros2.enabled': must be true or false"), std::string::npos) << e;
}

TEST(DaemonConfig, AMapTopicReplacesTheMapFile) {
  TempDir dir;
  const std::string head = "agent = \"bravo\"\ndiscovery_port = 17500\n";
  const std::string peers = "[[peer]]\nid = \"alpha\"\nhost = \"1.2.3.4\"\nport = 17600\n";
  std::ofstream(dir / "c.toml") << head << peers << "[ros2]\nmap_topic = \"/Laser_map\"\n";
  const Config c = loadConfig(dir / "c.toml");
  EXPECT_EQ(c.ros2.map_topic, "/Laser_map");
  EXPECT_TRUE(c.map.empty());
  EXPECT_NE(describe(c).find("ros2.map_topic = /Laser_map"), std::string::npos) << describe(c);

  std::string e = errorOf(dir, head + peers);
  EXPECT_NE(e.find("key 'map' is required"), std::string::npos) << "neither a file nor a topic: " << e;
  e = errorOf(dir, head + "map = \"a.pcd\"\n" + peers + "[ros2]\nmap_topic = \"/Laser_map\"\n");
  EXPECT_NE(e.find("the map comes from one place"), std::string::npos) << e;
  for (const char* bad : {"/laser map", "/2d/map", "//map", "/map/", ""}) {
    e = errorOf(dir, head + peers + "[ros2]\nmap_topic = \"" + bad + "\"\n");
    if (std::string(bad).empty()) {
      EXPECT_NE(e.find("key 'map' is required"), std::string::npos) << "an empty topic is none: " << e;
      continue;
    }
    EXPECT_NE(e.find("is not a ROS 2 topic name"), std::string::npos) << bad << ": " << e;
  }
  e = errorOf(dir, head + peers + "[ros2]\nenabled = false\nmap_topic = \"/map\"\n");
  EXPECT_NE(e.find("needs [ros2] enabled"), std::string::npos) << e;
}

// The table is made from the settings' declarations (settings.hpp): print it
// with `tomomapd --config-reference` and paste it over the old one.
TEST(DaemonConfig, TheReferenceTableIsTheDeclaredSettings) {
  std::ifstream in(std::string(TOMOMAP_SOURCE_DIR) + "/docs/configuration.md");
  const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_FALSE(doc.empty());
  const std::string table = referenceTable();
  EXPECT_NE(doc.find(table), std::string::npos) << "docs/configuration.md's table is not this:\n" << table;
  size_t rows = 0;
  for (size_t at = doc.find("\n| `"); at != std::string::npos; at = doc.find("\n| `", at + 1)) ++rows;
  EXPECT_EQ(rows, settings().size()) << "one table row per setting, and no other table of keys";
}

TEST(DaemonConfig, ARangeIsOneRangeEverywhere) {
  // The daemon's [match] keys are the matcher's settings, with their ranges.
  for (const MatchSetting& m : matchSettings()) {
    const Setting& s = setting(m.key == "grid" ? "grid" : "match." + m.key);
    EXPECT_EQ(s.lo, m.lo) << s.key;
    EXPECT_EQ(s.hi, m.hi) << s.key;
    EXPECT_EQ(s.kind, m.kind) << s.key;
  }
  TempDir dir;
  const std::string base = "agent = \"alpha\"\nmap = \"a.pcd\"\ndiscovery_port = 17500\n[match]\n";
  EXPECT_NE(errorOf(dir, base + "max_features = 10001\n").find("must be a number from 1 to 10000"), std::string::npos);
  EXPECT_EQ(errorOf(dir, base + "threads = 1024\n"), "");
}

TEST(DaemonConfig, AReloadRejoinsForEveryNetworkSettingAndOnlyThose) {
  TempDir dir;
  const std::string base = "agent = \"alpha\"\nmap = \"a.pcd\"\ndiscovery_port = 17500\n";
  std::ofstream(dir / "c.toml") << base;
  const Config before = loadConfig(dir / "c.toml");
  std::ofstream(dir / "c.toml") << base << "bandwidth_kbps = 500\nclaim_timeout_s = 9\n[ros2]\ndomain = 3\n";
  const Config after = loadConfig(dir / "c.toml");
  EXPECT_EQ(changed(before, after, Reload::Rejoin), std::vector<std::string>{"bandwidth_kbps"});
  EXPECT_EQ(changed(before, after, Reload::AtOnce), std::vector<std::string>{"claim_timeout_s"});
  EXPECT_EQ(changed(before, after, Reload::RestartsRos2), (std::vector<std::string>{"ros2.enabled", "ros2.domain"}));
  // Every setting says what a reload does with it, and a field of the
  // transport is one a rejoin follows (no field compared by hand).
  for (const Setting& s : settings()) {
    if (s.key.rfind("peer.", 0) == 0 || s.key.rfind("security.", 0) == 0 || s.key == "domain" || s.key == "address" ||
        s.key.find("_port") != std::string::npos || s.key == "bandwidth_kbps") {
      EXPECT_EQ(s.reload, Reload::Rejoin) << s.key;
    }
  }
}

TEST(DaemonConfig, EveryShippedConfigLoads) {
  // The examples users copy, the local demo's and the containers' configs.
  // Copies, beside the keys the demo makes where they point (demo-out/keys).
  namespace fs = std::filesystem;
  TempDir dir;
  tomomap::fleet::FleetRequest keys;
  keys.out = dir / "demo-out/keys";
  keys.agents = {"alpha", "bravo", "charlie"};
  tomomap::fleet::makeFleet(keys);
  size_t n = 0;
  for (const char* folder : {"config", "config/local-3-agents", "docker/config"}) {
    fs::create_directories(dir / folder);
    for (const auto& e : fs::directory_iterator(std::string(TOMOMAP_SOURCE_DIR) + "/" + folder)) {
      if (e.path().extension() != ".toml") continue;
      ++n;
      const fs::path copy = fs::path(dir / folder) / e.path().filename();
      fs::copy_file(e.path(), copy);
      EXPECT_NO_THROW(loadConfig(copy.string())) << e.path();
    }
  }
  EXPECT_GE(n, 7u);
  EXPECT_TRUE(loadConfig(dir / "config/local-3-agents/alpha.toml").transport.security.enabled())
      << "the demo is secure";
}

TEST(DaemonConfig, SecurityFilesMustExistAndBeComplete) {
  TempDir dir;
  const std::string base = "agent = \"alpha\"\nmap = \"a.pcd\"\ndiscovery_port = 17500\n[security]\n";
  EXPECT_NE(errorOf(dir, base + "ca = \"nope.pem\"\n").find("c.toml:5:6: key 'security.ca': no such file"),
            std::string::npos)
      << errorOf(dir, base + "ca = \"nope.pem\"\n");
  std::ofstream(dir / "ca.pem") << "x";
  EXPECT_NE(errorOf(dir, base + "ca = \"ca.pem\"\n").find("key 'security.certificate' is required"), std::string::npos)
      << errorOf(dir, base + "ca = \"ca.pem\"\n");
  EXPECT_NE(errorOf(dir, base + "cert = \"ca.pem\"\n").find("key 'security.cert': unknown key"), std::string::npos);
}

TEST(DaemonConfig, TestFaultsComeFromTheEnvironmentOnly) {
  const daemon::TestFaults f = daemon::parseTestFaults("drop_percent=10,wrong_pair=bravo<-delta");
  EXPECT_EQ(f.drop_percent, 10);
  EXPECT_EQ(f.wrong_pair, "bravo<-delta");
  EXPECT_EQ(f.text(), "drop_percent=10,wrong_pair=bravo<-delta");
  EXPECT_FALSE(daemon::parseTestFaults("").any());
  for (const char* bad : {"drop_percent=95", "drop_percent=x", "wrong_pair=bravo", "slow=1", "drop_percent"}) {
    try {
      daemon::parseTestFaults(bad);
      ADD_FAILURE() << bad << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("TOMOMAPD_TEST_FAULTS"), std::string::npos) << e.what();
    }
  }
  // The config file has no such keys.
  TempDir dir;
  const std::string base = "agent = \"bravo\"\nmap = \"a.pcd\"\ndiscovery_port = 17500\n";
  for (const char* key : {"test_drop_percent = 10\n", "test_wrong_pair = \"bravo<-alpha\"\n"}) {
    const std::string e = errorOf(dir, base + key);
    EXPECT_NE(e.find("unknown key"), std::string::npos) << e;
  }
}
