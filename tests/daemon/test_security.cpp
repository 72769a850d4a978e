// Who may speak for an agent. Real daemons, and an intruder that is a real
// Fast DDS participant in this test process, forging estimates on the wire.
#include <gtest/gtest.h>
#include <zlib.h>

#include <atomic>
#include <cmath>
#include <fstream>
#include <random>

#include "fleet.hpp"
#include "fleet/fleet_keys.hpp"
#include "transport/bus.hpp"
#include "transport/estimate_wire.hpp"
#include "transport/map_offer.hpp"
#include "transport/slice_encoding.hpp"

using namespace tomomap;
using namespace tomomap::test;
using namespace std::chrono_literals;

namespace {

/// Memory figures mean nothing under AddressSanitizer (shadow memory, a
/// quarantine of freed blocks): there the memory bounds are not checked.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kMeasuresMemory = false;
#else
constexpr bool kMeasuresMemory = true;
#endif

/// A participant of our own making that joins the fleet's peers as `name`.
struct Intruder {
  std::atomic<int> peers_up{0};
  std::atomic<int> bravo_read{0};  ///< bravo's announcements it received
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
    h.announcement = [this](wire::MapAnnouncement&& a) { bravo_read += a.agent().to_string() == "bravo"; };
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
  return {dir + "/" + F::ca,         dir + "/" + F::certificate, dir + "/" + F::private_key,
          dir + "/" + F::governance, dir + "/" + F::permissions, ""};
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
  Intruder mallory("mallory", fleet.port(10),
                   {{"alpha", "127.0.0.1", fleet.port(0)}, {"bravo", "127.0.0.1", fleet.port(1)}});
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
  Intruder plain("alpha", fleet.port(16), peers);
  plain.forge(real, "alpha");
  Intruder liar("alpha", fleet.port(12), peers, robotFiles(dir / "keys/charlie"));
  liar.forge(real, "alpha");
  Intruder charlie("charlie", fleet.port(14), peers, robotFiles(dir / "keys/charlie"));
  charlie.forge(real, "alpha");

  EXPECT_TRUE(Fleet::waitFor([&] { return charlie.peers_up >= 2; }, 60s)) << "charlie authenticates";
  for (const std::string id : {"alpha", "bravo"}) {
    EXPECT_TRUE(Fleet::waitFor([&] { return statusCount(fleet, id, "refused_participants") > 0; }, 60s))
        << id << " refuses the participant of charlie that names itself alpha\n"
        << fleet.log(id);
    EXPECT_TRUE(Fleet::waitFor([&] { return statusCount(fleet, id, "dropped_impostor_samples") > 0; }, 60s))
        << id << " drops charlie's estimate in alpha's name\n"
        << fleet.log(id);
  }
  // The counter above may come from the stranger's failed handshake too: wait
  // for the liar's own refusal.
  for (const std::string id : {"alpha", "bravo"})
    EXPECT_TRUE(Fleet::waitFor(
        [&] { return fleet.log(id).find("names itself alpha but is authenticated as charlie") != std::string::npos; },
        60s))
        << fleet.log(id);
  // The stranger started first and had as long as the others: it never got in.
  EXPECT_EQ(stranger.peers_up, 0) << "a certificate from another CA does not authenticate";
  EXPECT_TRUE(Fleet::waitFor([&] { return charlie.bravo_read > 0; }, 60s)) << "a fleet member reads the topics";
  EXPECT_EQ(stranger.bravo_read, 0) << "the stranger reads none of the topics";
  EXPECT_EQ(plain.bravo_read, 0) << "a participant without security reads none of the topics";
  for (const std::string id : {"alpha", "bravo"}) {
    const auto kept = fleet.transforms(id).at("alpha<-bravo");
    EXPECT_EQ(kept["T_target_source"]["x"], real["T_target_source"]["x"]) << id << " kept the true transform";
    EXPECT_EQ(kept["computed_by"], real["computed_by"]);
  }
}

namespace {

/// Resident and peak memory of a process [kB], from /proc.
std::pair<long, long> memoryKb(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  long rss = 0, peak = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmRSS:", 0) == 0) rss = std::stol(line.substr(6));
    if (line.rfind("VmHWM:", 0) == 0) peak = std::stol(line.substr(6));
  }
  return {rss, peak};
}

/// alpha alone, with a synth map, listing bravo, whose daemon never starts:
/// an intruder can take bravo's name, and its samples pass the identity check.
void startAlphaBesideAbsentBravo(TempDir& dir, Fleet& fleet) {
  ASSERT_EQ(runTomomap("synth -o " + (dir / "world") + " -n 1 --noise low -s 3 --scale 0.5").exit_code, 0);
  const std::vector<AgentSpec> agents{{"alpha", dir / "world/map_0.pcd"}, {"bravo", dir / "absent.pcd"}};
  fleet.start(agents[0], agents);
  ASSERT_TRUE(Fleet::waitFor([&] { return fleet.log("alpha").find("ready:") != std::string::npos; }, 60s))
      << fleet.log("alpha");
}

}  // namespace

TEST(Identity, AHundredThousandFuzzedSamplesCrashNothingAndLeaveMemoryFlat) {
  TempDir dir;
  Fleet fleet(dir);
  // The fuzzer takes bravo's name, so every sample reaches validation.
  ASSERT_NO_FATAL_FAILURE(startAlphaBesideAbsentBravo(dir, fleet));
  Intruder fuzzer("bravo", fleet.port(10), {{"alpha", "127.0.0.1", fleet.port(0)}});
  ASSERT_TRUE(Fleet::waitFor([&] { return fuzzer.peers_up >= 1; }, 60s));
  ASSERT_TRUE(Fleet::waitFor([&] { return fleet.log("alpha").find("peer bravo is up") != std::string::npos; }, 60s));
  const long rss_before = memoryKb(fleet.pid("alpha")).first;

  std::mt19937_64 rng(12345);
  auto any = [&](uint64_t n) { return n ? rng() % n : rng(); };
  auto anyDouble = [&] {
    const double pick[] = {0.0, -1.0, 1e300, std::nan(""), INFINITY, 0.05, -1e-300};
    return any(3) == 0 ? pick[any(7)] : std::ldexp(static_cast<double>(any(0)), static_cast<int>(any(200)) - 100);
  };
  constexpr int kSamples = 100000;
  for (int i = 0; i < kSamples; ++i) {
    switch (i % 5) {
      case 0: {
        wire::MapAnnouncement a;
        a.agent("bravo");
        a.version(any(0));
        a.grid(anyDouble());
        a.x_min(anyDouble());
        a.width(static_cast<uint16_t>(any(0)));
        a.height(static_cast<uint16_t>(any(0)));
        a.slice_count(static_cast<int32_t>(any(0)));
        for (uint64_t s = any(8); s > 0; --s) {
          wire::SliceEntry e;
          e.slice(static_cast<int32_t>(any(0)));
          e.parts(static_cast<uint16_t>(any(0)));
          e.bytes(static_cast<uint32_t>(any(0)));
          a.slices().push_back(e);
        }
        fuzzer.bus->publish(a);
        break;
      }
      case 1: {
        wire::SliceFeatures s;
        s.agent("bravo");
        s.version(any(4));
        s.slice(static_cast<int32_t>(any(1000)));
        s.part(static_cast<uint16_t>(any(10)));
        s.parts(static_cast<uint16_t>(any(0)));
        s.encoding(any(2) ? wire::SliceEncoding::FEATURES : wire::SliceEncoding::OCCUPANCY);
        for (uint64_t k = any(20); k > 0; --k) {
          wire::Feature f;
          f.u(static_cast<uint16_t>(any(0)));
          f.v(static_cast<uint16_t>(any(0)));
          s.features().push_back(f);
        }
        for (uint64_t k = any(200); k > 0; --k) s.occupancy().push_back(static_cast<uint8_t>(any(256)));
        fuzzer.bus->publish(s);
        break;
      }
      case 2: {
        wire::ChunkRequest r;
        r.requester("bravo");
        r.owner(any(2) ? "alpha" : "zulu");
        r.version(any(0));
        r.stalled_ms(static_cast<uint32_t>(any(0)));
        r.received_through(any(0));
        for (uint64_t k = any(50); k > 0; --k) r.slices().push_back(static_cast<int32_t>(any(0)));
        fuzzer.bus->publish(r);
        break;
      }
      case 3: {
        wire::MatchClaim c;
        c.target(any(2) ? "alpha" : "zulu");
        c.source("bravo");
        c.target_version(any(0));
        c.source_version(any(0));
        c.claimer("bravo");
        fuzzer.bus->publish(c);
        break;
      }
      default: {
        wire::TransformEstimate e;
        e.target("alpha");
        e.source("bravo");
        e.target_version(any(0));
        e.source_version(any(0));
        e.reliable(any(2));
        e.x(anyDouble());
        e.yaw(anyDouble());
        e.answered_by(any(2) ? "features" : "no such search");
        e.lead_sigma(anyDouble());
        e.computed_by("bravo");
        fuzzer.bus->publish(e);
        break;
      }
    }
  }
  // Every kind was rejected, and the daemon still answers (status each second).
  EXPECT_TRUE(Fleet::waitFor([&] { return statusCount(fleet, "alpha", "rejected_samples") > 1000; }, 120s))
      << fleet.readJson("alpha", "status.json").dump(2);
  EXPECT_FALSE(fleet.waitExit("alpha", 100ms).has_value()) << "alive\n" << fleet.log("alpha");
  const auto [rss_after, peak] = memoryKb(fleet.pid("alpha"));
  if (kMeasuresMemory) {
    EXPECT_LT(rss_after - rss_before, 64 * 1024) << "RSS " << rss_before << " -> " << rss_after << " kB";
  }
  std::cerr << "alpha RSS " << rss_before << " kB before, " << rss_after << " kB after " << kSamples
            << " fuzzed samples; peak " << peak << " kB; rejected " << statusCount(fleet, "alpha", "rejected_samples")
            << "\n";
  EXPECT_TRUE(fleet.transforms("alpha").empty()) << "nothing stored from fuzz";
  EXPECT_LE(countOf(fleet.log("alpha"), "rejected"), 5u) << "one line, then a summary a minute\n" << fleet.log("alpha");
  stopAll(fleet, {"alpha"});
}

TEST(Identity, AnOccupancyBombInAPeersNameStaysWithinTheMemoryBudget) {
  // The bomb that once drove a daemon from 48 MB to 908 MB: an 8192 x 8192
  // raster, 4 slices, every cell occupied (8 kB deflated per slice, 268 MB
  // as a cell list each). A valid announcement in bravo's name, whose daemon
  // never starts, so only the memory budget (256 MB by default) stands.
  TempDir dir;
  Fleet fleet(dir);
  ASSERT_NO_FATAL_FAILURE(startAlphaBesideAbsentBravo(dir, fleet));
  Intruder bomber("bravo", fleet.port(10), {{"alpha", "127.0.0.1", fleet.port(0)}});

  constexpr int kSide = 8192, kSlices = 4;
  std::vector<uint8_t> raster(transport::rasterBytes(kSide, kSide), 0xff);
  uLongf size = compressBound(static_cast<uLong>(raster.size()));
  std::vector<uint8_t> full(size);
  ASSERT_EQ(compress2(full.data(), &size, raster.data(), static_cast<uLong>(raster.size()), 9), Z_OK);
  full.resize(size);
  wire::MapAnnouncement a;
  a.agent("bravo");
  a.grid(0.05);
  a.width(kSide);
  a.height(kSide);
  a.slice_count(kSlices);
  a.raw_bytes(1u << 30);
  a.up({0.0, 0.0, 1.0});
  a.features().max_features(1000);
  a.features().fast_threshold(20);
  a.features().pad(16);
  for (int i = 0; i < kSlices; ++i) {
    wire::SliceEntry e;
    e.slice(i);
    e.parts(1);
    e.bytes(static_cast<uint32_t>(full.size()));
    e.crc32(transport::crcOf(full));
    a.slices().push_back(e);
  }
  a.version(transport::mapVersion(a));
  ASSERT_FALSE(transport::validate(a)) << transport::validate(a).text();
  // Sent again until it lands, as an attacker would: samples published before
  // alpha's reader of that topic has matched the bomber's writer are lost.
  const auto refused = [&] {
    return fleet.log("alpha").find("more memory than peer_memory_mb allows") != std::string::npos;
  };
  const auto deadline = std::chrono::steady_clock::now() + 120s;
  while (!refused() && std::chrono::steady_clock::now() < deadline) {
    bomber.bus->publish(a);
    for (int i = 0; i < kSlices; ++i) {
      wire::SliceFeatures s;
      s.agent("bravo");
      s.version(a.version());
      s.slice(i);
      s.part(0);
      s.parts(1);
      s.encoding(wire::SliceEncoding::OCCUPANCY);
      s.occupancy(full);
      bomber.bus->publish(s);
    }
    Fleet::waitFor(refused, 5s);
  }
  EXPECT_TRUE(refused()) << fleet.log("alpha");
  const auto [rss, peak] = memoryKb(fleet.pid("alpha"));
  std::cerr << "alpha under the bomb: RSS " << rss << " kB, peak " << peak << " kB\n";
  if (kMeasuresMemory) {
    EXPECT_LT(peak, 256 * 1024) << "below the budget, and far below the 908 MB the bomb once took";
  }
  EXPECT_EQ(fleet.log("alpha").find("received the map of bravo"), std::string::npos);
  stopAll(fleet, {"alpha"});
}
