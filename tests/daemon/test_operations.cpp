// tomomapd as an operator runs it: under systemd's notify protocol, reloaded
// with SIGHUP, following a map file that a SLAM system rewrites.
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>

#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <random>
#include <regex>
#include <thread>

#include "core/gravity.hpp"
#include "fleet.hpp"
#include "io/map_io.hpp"
#include "results/agreed_transform.hpp"

using namespace tomomap;
using namespace tomomap::test;
using namespace std::chrono_literals;

namespace {

/// How long a daemon may take to describe its map and say READY=1: seconds
/// in a Release build, but a sanitizer build on a machine whose cores are
/// busy with other tests took over 30 s (a local CI run with an evaluation
/// beside it).
constexpr auto kReady = 120s;

/// The receiving end of NOTIFY_SOCKET, as systemd binds it. It reads all the
/// time, as systemd does: a datagram socket holds only ~10 unread messages
/// (net.unix.max_dgram_qlen), and a daemon whose watchdog pings go unread
/// blocks in sd_notify.
class NotifySocket {
 public:
  explicit NotifySocket(const std::string& path) : path_(path) {
    fd_ = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::snprintf(a.sun_path, sizeof a.sun_path, "%s", path.c_str());
    if (bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) ADD_FAILURE() << "cannot bind " << path;
    reader_ = std::thread([this] { read(); });
  }
  ~NotifySocket() {
    stop_ = true;
    reader_.join();
    close(fd_);
  }

  /// Waits until a message not yet waited for contains `wanted`.
  bool waitFor(const std::string& wanted, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    return arrived_.wait_for(lock, timeout, [&] {
      for (size_t i = seen_; i < messages_.size(); ++i)
        if (messages_[i].find(wanted) != std::string::npos) {
          seen_ = i + 1;
          return true;
        }
      return false;
    });
  }
  /// Messages received so far that contain `wanted`.
  size_t count(const std::string& wanted) {
    std::lock_guard lock(mutex_);
    size_t n = 0;
    for (const auto& m : messages_) n += m.find(wanted) != std::string::npos;
    return n;
  }
  std::string all() {
    std::lock_guard lock(mutex_);
    std::string s;
    for (const auto& m : messages_) s += m + "\n";
    return s;
  }
  std::string env() const { return "NOTIFY_SOCKET=" + path_; }

 private:
  void read() {
    while (!stop_) {
      pollfd p{fd_, POLLIN, 0};
      if (poll(&p, 1, 50) <= 0) continue;
      char buf[4096];
      const ssize_t n = recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) continue;
      std::lock_guard lock(mutex_);
      messages_.emplace_back(buf, static_cast<size_t>(n));
      arrived_.notify_all();
    }
  }

  std::string path_;
  int fd_ = -1;
  std::mutex mutex_;
  std::condition_variable arrived_;
  std::vector<std::string> messages_;
  size_t seen_ = 0;
  std::atomic<bool> stop_{false};
  std::thread reader_;
};

void replaceIn(const std::string& path, const std::string& from, const std::string& to) {
  std::string text = readText(path);
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from << " not in " << path;
  text.replace(at, from.size(), to);
  std::ofstream(path) << text;
}

/// Writes `points` beside `path` and renames them over it, as a SLAM system
/// replaces its map file in one step.
void replaceMap(const std::string& path, const Points& points) {
  savePcd(path + ".tmp", points);
  std::filesystem::rename(path + ".tmp", path);
}

/// alpha on demo-pcd1 and bravo on a copy of demo-pcd2 in `dir` (bravo.pcd,
/// where a test can rewrite it), started and agreed on their pair.
std::vector<AgentSpec> startDemoPairWithBravosMapInDir(Fleet& fleet, const TempDir& dir, const Points& bravo) {
  const std::string d = demoRoom() + "/";
  savePcd(dir / "bravo.pcd", bravo);
  const std::vector<AgentSpec> agents{{"alpha", d + "demo-pcd1.pcd"}, {"bravo", dir / "bravo.pcd"}};
  for (const auto& a : agents) fleet.start(a, agents);
  EXPECT_TRUE(fleet.waitForTransforms({"alpha", "bravo"}, 1, 60s)) << fleet.log("alpha") << fleet.log("bravo");
  return agents;
}

}  // namespace

TEST(Operations, NotifiesSystemdReloadsOnSighupAndStopsCleanly) {
  TempDir dir;
  const auto gen = runTomomap("synth -o " + (dir / "world") + " -n 1 --noise low -s 3 --scale 0.5");
  ASSERT_EQ(gen.exit_code, 0) << gen.output;
  NotifySocket notify(dir / "notify.sock");
  Fleet fleet(dir);
  // bravo is configured but never starts: the daemon serves regardless.
  const std::vector<AgentSpec> agents{{"alpha", dir / "world/map_0.pcd"}, {"bravo", dir / "absent.pcd"}};
  fleet.start(agents[0], agents, {notify.env(), "WATCHDOG_USEC=400000"});

  ASSERT_TRUE(notify.waitFor("READY=1", kReady)) << notify.all() << fleet.log("alpha");
  // READY comes once the own features are announced: the log says so before.
  EXPECT_NE(fleet.log("alpha").find("ready: announced version"), std::string::npos);
  ASSERT_TRUE(notify.waitFor("STATUS=0/1 peers up", 30s)) << notify.all();
  EXPECT_TRUE(Fleet::waitFor([&] { return notify.count("WATCHDOG=1") >= 3; }, 30s))
      << "pings every 0.2 s with WatchdogSec=0.4 s\n"
      << notify.all();

  // The operator's view, from the state directory.
  const std::string state = dir / "out-alpha";
  const auto human = runTomomap("status " + state);
  EXPECT_EQ(human.exit_code, 0) << human.output;
  EXPECT_NE(human.output.find("tomomapd alpha: running"), std::string::npos) << human.output;
  EXPECT_NE(human.output.find("bravo"), std::string::npos);
  EXPECT_NE(human.output.find("down"), std::string::npos) << "bravo never started";
  const auto machine = runTomomap("status --json " + state);
  ASSERT_EQ(machine.exit_code, 0) << machine.output;
  const auto j = nlohmann::json::parse(machine.output.substr(machine.output.find('{')));
  EXPECT_TRUE(j["running"].get<bool>());
  EXPECT_EQ(j["status"]["agent"], "alpha");
  EXPECT_FALSE(j["status"]["peers"]["bravo"]["alive"].get<bool>());
  EXPECT_EQ(keysOf(j), (std::set<std::string>{"schema_version", "running", "status", "transforms", "frame"}));
  EXPECT_EQ(keysOf(j["status"]), documentedJsonFields("`status.json`")) << "status.json as docs/json.md lists it";
  EXPECT_EQ(keysOf(fleet.readJson("alpha", "transforms.json")), documentedJsonFields("`transforms.json`"));
  EXPECT_EQ(keysOf(j["frame"]), documentedJsonFields("`frame.json`")) << "frame.json as docs/json.md lists it";

  // SIGHUP applies a changed config and reads the (unchanged) map again.
  const std::string config = dir / "alpha.toml";
  replaceIn(config, "request_interval_s = 1", "request_interval_s = 2.5");
  fleet.kill("alpha", SIGHUP);
  ASSERT_TRUE(notify.waitFor("RELOADING=1", 30s)) << notify.all();
  ASSERT_TRUE(notify.waitFor("READY=1", kReady)) << notify.all();
  EXPECT_TRUE(Fleet::waitFor(
      [&] {
        return fleet.log("alpha").find("version") != std::string::npos &&
               fleet.log("alpha").find("stays") != std::string::npos;
      },
      30s))
      << fleet.log("alpha");
  EXPECT_NE(fleet.log("alpha").find("request_interval_s = 2.5"), std::string::npos) << fleet.log("alpha");

  // A broken config is refused with its line; the daemon keeps running.
  std::ofstream(config, std::ios::app) << "grid = \"fine\"\n";
  fleet.kill("alpha", SIGHUP);
  ASSERT_TRUE(notify.waitFor("READY=1", kReady)) << notify.all();
  EXPECT_NE(fleet.log("alpha").find("reload refused"), std::string::npos) << fleet.log("alpha");
  EXPECT_NE(fleet.log("alpha").find("alpha.toml:"), std::string::npos);
  EXPECT_FALSE(fleet.waitExit("alpha", 500ms).has_value()) << "still running";

  fleet.kill("alpha", SIGTERM);
  const auto code = fleet.waitExit("alpha", stopTimeout());
  ASSERT_TRUE(code.has_value()) << "stops within the unit's TimeoutStopSec";
  EXPECT_EQ(*code, 0);
  EXPECT_TRUE(notify.waitFor("STOPPING=1", 5s)) << notify.all();
  EXPECT_EQ(fleet.readJson("alpha", "status.json")["agent"], "alpha");
  const auto after = runTomomap("status " + state);
  EXPECT_EQ(after.exit_code, 1) << after.output;
  EXPECT_NE(after.output.find("NOT RUNNING"), std::string::npos) << after.output;
}

TEST(Operations, ADaemonBootedBeforeItsMapWaitsForItThenMatches) {
  // At boot the SLAM system may not have written the map yet: the service
  // must come up, say what it waits for, and match once the file appears.
  REQUIRE_DEMO_ROOM();
  TempDir dir;
  const std::string d = demoRoom() + "/";
  const std::string bravo_map = dir / "bravo.pcd";
  NotifySocket notify(dir / "notify.sock");
  Fleet fleet(dir);
  const std::vector<AgentSpec> agents{{"alpha", d + "demo-pcd1.pcd"}, {"bravo", bravo_map}};
  fleet.start(agents[1], agents, {notify.env()});
  fleet.start(agents[0], agents);

  ASSERT_TRUE(notify.waitFor("READY=1", kReady)) << notify.all() << fleet.log("bravo");
  // STATUS follows READY: wait for it rather than assume it came in the same breath.
  EXPECT_TRUE(notify.waitFor("STATUS=waiting for map " + bravo_map, 30s)) << notify.all();
  EXPECT_NE(fleet.log("bravo").find("ready: joined 1 peers; waiting for map " + bravo_map), std::string::npos)
      << fleet.log("bravo");
  EXPECT_TRUE(fleet.readJson("bravo", "status.json")["map"]["waiting"].get<bool>());
  const auto human = runTomomap("status " + (dir / "out-bravo"));
  EXPECT_NE(human.output.find("WAITING"), std::string::npos) << human.output;
  // Nothing to match yet: bravo offers no map, and nobody stores a transform.
  EXPECT_FALSE(fleet.waitExit("bravo", 1000ms).has_value()) << "waits, does not exit";
  EXPECT_TRUE(fleet.transforms("alpha").empty());

  replaceMap(bravo_map, loadMap(d + "demo-pcd2.pcd"));
  ASSERT_TRUE(fleet.waitForTransforms({"alpha", "bravo"}, 1, 90s)) << fleet.log("alpha") << fleet.log("bravo");
  const auto t = fleet.transforms("bravo").at("alpha<-bravo");
  EXPECT_TRUE(t["reliable"].get<bool>()) << t.dump(2);
  const Pose4 gt = groundTruth(d + "demo-pcd1-gtpose.txt", d + "demo-pcd2-gtpose.txt");
  EXPECT_LT(poseError(poseOf(t), gt).translation, 0.05);
  EXPECT_FALSE(fleet.readJson("bravo", "status.json")["map"]["waiting"].get<bool>());
  stopAll(fleet, {"alpha", "bravo"});
}

TEST(Operations, ARewrittenMapIsAgreedAgainWithASmallerResend) {
  REQUIRE_DEMO_ROOM();
  TempDir dir;
  const std::string d = demoRoom() + "/";
  // bravo's SLAM map lives in the test folder, where the test can rewrite it.
  const Points original = loadMap(d + "demo-pcd2.pcd");
  const std::string bravo_map = dir / "bravo.pcd";
  Fleet fleet(dir);
  startDemoPairWithBravosMapInDir(fleet, dir, original);
  if (HasFailure()) return;
  const std::string v1 = fleet.readJson("bravo", "status.json")["map"]["version"];
  const size_t sent_first = fleet.readJson("bravo", "status.json")["sent"]["bytes"];

  // The robot maps a cabinet, inside the map's bounds.
  const std::string staged = dir / "bravo.pcd.tmp";
  savePcd(staged, withCabinet(original));
  // First a writer that is cut off half-way, in place: the daemon must keep its map.
  const std::string bytes = readText(staged);
  std::ofstream(bravo_map, std::ios::binary | std::ios::trunc) << bytes.substr(0, bytes.size() / 2);
  ASSERT_TRUE(Fleet::waitFor([&] { return fleet.log("bravo").find("cannot be used") != std::string::npos; }, 30s))
      << fleet.log("bravo");
  EXPECT_EQ(fleet.readJson("bravo", "status.json")["map"]["version"], v1);
  // Then the complete map, written beside it and renamed over it.
  std::filesystem::rename(staged, bravo_map);

  const std::string v2 = waitForReagreement(fleet, {"alpha", "bravo"}, "alpha<-bravo", "bravo", v1, 60s);
  ASSERT_FALSE(v2.empty()) << fleet.log("alpha") << fleet.log("bravo");

  const auto t = fleet.transforms("alpha").at("alpha<-bravo");
  ASSERT_TRUE(t["reliable"].get<bool>()) << t.dump(2);
  const Pose4 gt = groundTruth(d + "demo-pcd1-gtpose.txt", d + "demo-pcd2-gtpose.txt");
  EXPECT_LT(poseError(poseOf(t), gt).translation, 0.05);
  EXPECT_EQ(fleet.transforms("bravo").at("alpha<-bravo")["T_target_source"], t["T_target_source"]);

  // Only the changed slices travelled the second time.
  const auto s = fleet.readJson("alpha", "status.json");
  const auto& transfers = s["peers"]["bravo"]["transfers"];
  ASSERT_EQ(transfers.size(), 2u) << s.dump(2);
  EXPECT_EQ(transfers[1]["version"], v2);
  EXPECT_GT(transfers[1]["slices_reused"].get<int>(), 0);
  EXPECT_LT(transfers[1]["bytes"].get<size_t>(), transfers[0]["bytes"].get<size_t>()) << transfers.dump(2);
  const size_t sent_total = fleet.readJson("bravo", "status.json")["sent"]["bytes"];
  EXPECT_LT(sent_total - sent_first, sent_first) << "the resend is smaller than the first transfer";
  // And bravo described only what the cabinet changed: ORB and encoding on those slices alone.
  const std::string log = fleet.log("bravo");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(log, m, std::regex("ORB on ([0-9]+) of ([0-9]+) slices, ([0-9]+) of ([0-9]+) encoded")))
      << log;
  const int orb = std::stoi(m[1]), occupied = std::stoi(m[2]), encoded = std::stoi(m[3]), offered = std::stoi(m[4]);
  EXPECT_GT(orb, 0);
  EXPECT_LT(orb, occupied);
  EXPECT_LT(encoded, offered);
  EXPECT_GE(encoded, transfers[1]["slices"].get<int>() - transfers[1]["slices_reused"].get<int>())
      << "every slice alpha had to fetch again was encoded again";
  std::printf("bravo's update: ORB on %d of %d slices, %d of %d encoded\n", orb, occupied, encoded, offered);
  std::printf(
      "first transfer %zu B (%d slices); after the update %zu B (%d of %d slices reused); bravo sent %zu then "
      "%zu B\n",
      transfers[0]["bytes"].get<size_t>(), transfers[0]["slices"].get<int>(), transfers[1]["bytes"].get<size_t>(),
      transfers[1]["slices_reused"].get<int>(), transfers[1]["slices"].get<int>(), sent_first, sent_total - sent_first);
  const auto view = runTomomap("status " + (dir / "out-alpha"));
  EXPECT_NE(view.output.find(std::to_string(transfers[1]["slices_reused"].get<int>()) + " kept from its previous"),
            std::string::npos)
      << view.output;
  EXPECT_EQ(view.output.find("STALE"), std::string::npos) << "the agreed transform is for the current maps";
  // One computation per version of the pair, fleet-wide.
  EXPECT_EQ(matchesComputedReaching(fleet, {"alpha", "bravo"}, 2), 2);
  // The second matched again only the slice pairs with a changed slice.
  const std::regex computed(R"(computed alpha<-bravo in ([0-9.]+) s \(([0-9]+) slice pairs, ([0-9]+) kept)");
  std::vector<std::smatch> runs;
  const std::string logs = fleet.log("alpha") + fleet.log("bravo");
  for (std::sregex_iterator it(logs.begin(), logs.end(), computed), end; it != end; ++it) runs.push_back(*it);
  ASSERT_EQ(runs.size(), 2u) << logs;
  EXPECT_EQ(std::stoul(runs[0][3]), 0u) << runs[0].str();
  const size_t pairs = std::stoul(runs[1][2]), kept = std::stoul(runs[1][3]);
  EXPECT_GT(kept, pairs / 2) << runs[1].str() << ": most slices did not change";
  EXPECT_LT(kept, pairs) << runs[1].str() << ": the cabinet's slices did";
  std::printf("matching: first %s s (%s slice pairs), after the update %s s (%zu of %zu kept)\n",
              runs[0][1].str().c_str(), runs[0][2].str().c_str(), runs[1][1].str().c_str(), kept, pairs);
  stopAll(fleet, {"alpha", "bravo"});
}

TEST(Operations, ALeaningMapIsLevelledAndAgreedAgainButNeitherJunkNorAMapLeaningTooFarReplacesTheAgreedTransform) {
  REQUIRE_DEMO_ROOM();
  TempDir dir;
  const Points original = loadMap(demoRoom() + "/demo-pcd2.pcd");
  const std::string bravo_map = dir / "bravo.pcd";
  Fleet fleet(dir);
  const auto agents = startDemoPairWithBravosMapInDir(fleet, dir, original);
  if (HasFailure()) return;
  EXPECT_NE(fleet.log("bravo").find("; tilt 0."), std::string::npos) << "the own map's tilt is logged\n"
                                                                     << fleet.log("bravo");
  const auto status = fleet.readJson("bravo", "status.json");
  const std::string v1 = status["map"]["version"];
  EXPECT_LT(status["map"]["tilt_deg"].get<double>(), 1.0);
  EXPECT_FALSE(status["map"]["levelled"].get<bool>());
  const Eigen::Matrix4d level_answer =
      matrixFromJson(fleet.transforms("alpha").at("alpha<-bravo")["T_target_source_6dof"]);

  // The SLAM system restarts with its first IMU frame leaning 5 degrees: the
  // daemon levels the map, offers it, and the pair is agreed again; the whole
  // transform between the maps' own frames takes the lean in, and says bravo's up.
  const Eigen::AngleAxisd lean(radians(5), Eigen::Vector3d::UnitX());
  const Points rolled = rotatePoints(original, Eigen::Quaterniond(lean));
  replaceMap(bravo_map, rolled);
  std::string v2;
  ASSERT_TRUE(Fleet::waitFor(
      [&] {
        v2 = fleet.readJson("bravo", "status.json")["map"].value("version", v1);
        if (v2 == v1) return false;
        for (const char* id : {"alpha", "bravo"}) {
          const auto t = fleet.transforms(id);
          if (!t.count("alpha<-bravo") || t.at("alpha<-bravo")["source_version"] != v2) return false;
        }
        return true;
      },
      90s))
      << fleet.log("alpha") << fleet.log("bravo");
  EXPECT_NE(fleet.log("bravo").find("levelled: it leaned "), std::string::npos) << fleet.log("bravo");
  const auto leaning = fleet.readJson("bravo", "status.json")["map"];
  EXPECT_TRUE(leaning["levelled"].get<bool>());
  EXPECT_NEAR(leaning["tilt_deg"].get<double>(), 5.0, 0.5);
  const auto agreed = fleet.transforms("alpha").at("alpha<-bravo");
  ASSERT_TRUE(agreed["reliable"].get<bool>()) << agreed.dump(2);
  EXPECT_EQ(agreed, fleet.transforms("bravo").at("alpha<-bravo")) << "both hold the same agreement";
  const Eigen::Vector3d bravo_up(agreed["source_up"][0], agreed["source_up"][1], agreed["source_up"][2]);
  EXPECT_LT(degrees(std::acos(bravo_up.dot(lean * Eigen::Vector3d::UnitZ()))), 0.5) << agreed.dump(2);
  // The level map's answer, with the lean undone: p_alpha = T_level * lean^-1 * p_rolled.
  Eigen::Matrix4d unroll = Eigen::Matrix4d::Identity();
  unroll.topLeftCorner<3, 3>() = lean.inverse().toRotationMatrix();
  const Eigen::Matrix4d expected = level_answer * unroll;
  const Eigen::Matrix4d whole = matrixFromJson(agreed["T_target_source_6dof"]);
  const Eigen::Matrix3d turn = expected.topLeftCorner<3, 3>().transpose() * whole.topLeftCorner<3, 3>();
  EXPECT_LT(degrees(Eigen::AngleAxisd(turn).angle()), 0.5) << whole << "\nexpected\n" << expected;
  // Over the map, not at one point: its points land within 2 cells of where the level answer puts them.
  double farthest = 0;
  for (size_t i = 0; i < rolled.size(); i += 97) {
    const Eigen::Vector4d q(rolled[i].x(), rolled[i].y(), rolled[i].z(), 1.0);
    farthest = std::max(farthest, (whole * q - expected * q).norm());
  }
  EXPECT_LT(farthest, 0.10);
  std::printf("levelled 5 deg roll: the whole transform %.3f deg and at most %.3f m from the level answer's\n",
              degrees(Eigen::AngleAxisd(turn).angle()), farthest);

  // Then a level map that matches nothing (a SLAM session gone wrong: scattered
  // returns): offered, matched, no reliable match, and the agreed transform stays.
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 5.0f);
  Points junk;
  for (int i = 0; i < 60000; ++i) junk.emplace_back(u(rng), u(rng), 0.6f * u(rng));
  replaceMap(bravo_map, junk);
  const auto kept = [&](const std::string& id) {
    for (const auto& p : fleet.readJson(id, "status.json").value("pairs", nlohmann::json::array()))
      if (p.value("pair", "") == "alpha<-bravo" && p.value("state", "") == "kept") return true;
    return false;
  };
  ASSERT_TRUE(Fleet::waitFor([&] { return kept("alpha") && kept("bravo"); }, 60s))
      << fleet.log("alpha") << fleet.log("bravo");
  EXPECT_NE(fleet.readJson("bravo", "status.json")["map"]["version"], v2) << "the junk map is offered";
  for (const char* id : {"alpha", "bravo"}) {
    EXPECT_EQ(fleet.transforms(id).at("alpha<-bravo")["T_target_source_6dof"], agreed["T_target_source_6dof"]) << id;
    EXPECT_NE(fleet.log(id).find("the reliable transform agreed for their earlier versions stays"), std::string::npos)
        << fleet.log(id);
  }
  const auto kept_view = runTomomap("status " + (dir / "out-alpha"));
  EXPECT_NE(kept_view.output.find("KEPT: for earlier maps"), std::string::npos) << kept_view.output;
  EXPECT_EQ(matchesComputedReaching(fleet, {"alpha", "bravo"}, 3), 3)
      << "the first agreement, the levelled map's and the junk map's, once each";

  // A map leaning 40 degrees (beyond the floors' cone, where its walls may
  // pass for floors, and the room has no lines to tell them apart): never
  // levelled, refused as an update, the last map staying on offer.
  const Points too_far =
      rotatePoints(original, Eigen::Quaterniond(Eigen::AngleAxisd(radians(40), Eigen::Vector3d::UnitX())));
  const std::string v3 = fleet.readJson("bravo", "status.json")["map"]["version"];
  replaceMap(bravo_map, too_far);
  ASSERT_TRUE(Fleet::waitFor(
      [&] { return !fleet.readJson("bravo", "status.json")["map"].value("update_refused", "").empty(); }, 60s))
      << fleet.log("bravo");
  EXPECT_NE(fleet.log("bravo").find("own map is tilted "), std::string::npos) << fleet.log("bravo");
  EXPECT_NE(fleet.log("bravo").find("too far to level by its planes alone"), std::string::npos) << fleet.log("bravo");
  EXPECT_EQ(fleet.readJson("bravo", "status.json")["map"]["version"], v3) << "the last map stays on offer";
  const auto view = runTomomap("status " + (dir / "out-bravo"));
  EXPECT_NE(view.output.find("NOT offered: "), std::string::npos) << view.output;
  stopAll(fleet, {"alpha", "bravo"});

  // Started on it, the daemon refuses it and says why: exit 2, which systemd does not restart.
  fleet.start(agents[1], agents);
  EXPECT_EQ(fleet.waitExit("bravo", 60s), 2);
  EXPECT_EQ(countOf(fleet.log("bravo"), "own map is tilted"), 2u) << "once refused as an update, once at start\n"
                                                                  << fleet.log("bravo");
}

namespace {

/// The pair's state in the status.json of `id`'s running process ("agreed",
/// "stale", ...), or "" (also while the file is still its previous run's).
std::string pairState(const Fleet& fleet, const std::string& id, const std::string& pair) {
  const auto status = fleet.readJson(id, "status.json");
  if (status.value("pid", 0) != fleet.pid(id)) return "";
  for (const auto& p : status.value("pairs", nlohmann::json::array()))
    if (p.value("pair", "") == pair) return p.value("state", "");
  return "";
}

}  // namespace

TEST(Operations, RestartedDaemonsKeepTheirAgreedTransformsWithoutComputingAgain) {
  REQUIRE_DEMO_ROOM();
  TempDir dir;
  Fleet fleet(dir);
  const auto agents = startDemoPairWithBravosMapInDir(fleet, dir, loadMap(demoRoom() + "/demo-pcd2.pcd"));
  if (HasFailure()) return;
  const auto agreed = fleet.transforms("bravo").at("alpha<-bravo");
  stopAll(fleet, {"alpha", "bravo"});

  // Both come back (a power cycle): each reads what it stored and neither matches again.
  for (const auto& a : agents) fleet.start(a, agents);
  for (const char* id : {"alpha", "bravo"})
    ASSERT_TRUE(Fleet::waitFor([&] { return pairState(fleet, id, "alpha<-bravo") == "agreed"; }, 60s)) << fleet.log(id);
  for (const char* id : {"alpha", "bravo"}) {
    EXPECT_EQ(countOf(fleet.log(id), "restored 1 transforms from "), 1u) << fleet.log(id);
    const auto t = fleet.transforms(id).at("alpha<-bravo");
    for (const char* field : {"T_target_source", "computed_by", "computed_at_ms", "matching_seconds", "quality"})
      EXPECT_EQ(t[field], agreed[field]) << id << ": " << field;
  }
  EXPECT_EQ(matchesComputed(fleet, {"alpha", "bravo"}), 0) << fleet.log("alpha") << fleet.log("bravo");
  stopAll(fleet, {"alpha", "bravo"});

  // A transforms.json cut off mid-write is set aside, not trusted, and the pair is agreed again.
  const std::string stored = dir / "out-alpha/transforms.json";
  const std::string text = readText(stored);
  std::ofstream(stored, std::ios::trunc) << text.substr(0, text.size() / 2);
  fleet.start(agents[0], agents);
  fleet.start(agents[1], agents);
  ASSERT_TRUE(Fleet::waitFor([&] { return pairState(fleet, "alpha", "alpha<-bravo") == "agreed"; }, 60s))
      << fleet.log("alpha");
  EXPECT_NE(fleet.log("alpha").find("cannot be read"), std::string::npos) << fleet.log("alpha");
  EXPECT_TRUE(std::filesystem::exists(stored + ".unreadable"));
  stopAll(fleet, {"alpha", "bravo"});
}

TEST(Operations, AFullOutputFolderCatchesUpOnceThereIsSpaceAgain) {
  REQUIRE_DEMO_ROOM();
  TempDir dir;
  const std::string out = dir / "out-alpha";
  std::filesystem::create_directories(out);
  // A real full file system: a small tmpfs (root only, as CI runs).
  if (std::system(("mount -t tmpfs -o size=256k tmpfs '" + out + "' 2>/dev/null").c_str()) != 0)
    GTEST_SKIP() << "mounting a tmpfs needs root";
  struct Unmount {
    std::string at;
    ~Unmount() { (void)std::system(("umount -l '" + at + "'").c_str()); }
  } unmount{out};
  {
    std::ofstream filler(out + "/filler", std::ios::binary);
    const std::string block(4096, 'x');
    for (int i = 0; i < 1000 && filler.write(block.data(), block.size()); ++i) filler.flush();
  }
  Fleet fleet(dir);
  savePcd(dir / "bravo.pcd", loadMap(demoRoom() + "/demo-pcd2.pcd"));
  const std::vector<AgentSpec> agents{{"alpha", demoRoom() + "/demo-pcd1.pcd"}, {"bravo", dir / "bravo.pcd"}};
  for (const auto& a : agents) fleet.start(a, agents);
  ASSERT_TRUE(fleet.waitForTransforms({"bravo"}, 1, 60s)) << fleet.log("bravo");
  ASSERT_TRUE(
      Fleet::waitFor([&] { return fleet.log("alpha").find("cannot write transforms.json") != std::string::npos; }, 30s))
      << fleet.log("alpha");
  EXPECT_TRUE(fleet.transforms("alpha").empty()) << "the disk is full";

  std::filesystem::remove(out + "/filler");
  ASSERT_TRUE(fleet.waitForTransforms({"alpha"}, 1, 30s)) << fleet.log("alpha");
  EXPECT_EQ(fleet.transforms("alpha").at("alpha<-bravo")["T_target_source"],
            fleet.transforms("bravo").at("alpha<-bravo")["T_target_source"]);
  ASSERT_TRUE(Fleet::waitFor([&] { return !fleet.readJson("alpha", "status.json").empty(); }, 30s));
  const auto status = fleet.readJson("alpha", "status.json");
  EXPECT_FALSE(status["transforms_unwritten"].get<bool>()) << status.dump(2);
  EXPECT_EQ(status["write_error"], "") << status.dump(2);
  EXPECT_NE(fleet.log("alpha").find("transforms.json written again"), std::string::npos) << fleet.log("alpha");
  stopAll(fleet, {"alpha", "bravo"});
}
