#pragma once
// Real tomomapd processes on loopback for the multi-process tests: configs
// written to a temporary folder, distinct ports per test process, and every
// process killed when the test ends, pass or fail.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>

#include "support.hpp"

namespace tomomap::test {

struct AgentSpec {
  std::string id, map;
  double grid = 0.05;
  double bandwidth_kbps = 10000;
  std::vector<std::string> peers;  ///< ids it lists; all of the fleet's others by default
  std::string extra;               ///< more config lines ("key = value\n")

  AgentSpec(std::string id_, std::string map_, double grid_ = 0.05, double kbps = 10000,
            std::vector<std::string> peers_ = {})
      : id(std::move(id_)), map(std::move(map_)), grid(grid_), bandwidth_kbps(kbps), peers(std::move(peers_)) {}
};

class Fleet {
 public:
  explicit Fleet(TempDir& dir) : dir_(dir) {
    // Ports apart per test process: ctest runs tests side by side. ctest
    // gives each chain of fleets a base of its own (tests/CMakeLists.txt);
    // elsewhere (a test run by hand beside another) the process id picks one.
    if (const char* base = std::getenv("TOMOMAP_TEST_PORT_BASE"))
      base_port_ = static_cast<uint16_t>(std::stoi(base));
    else
      base_port_ = static_cast<uint16_t>(23000 + (::getpid() % 400) * 40);
  }
  ~Fleet() {
    std::vector<std::string> ids;
    for (const auto& [id, pid] : pids_) ids.push_back(id);
    for (const auto& id : ids) kill(id, SIGKILL);
  }

  uint16_t port(size_t index) const { return static_cast<uint16_t>(base_port_ + 4 * index); }

  /// Written into every config: a claim without a result or renewal is void
  /// after this [s]; unset, the daemon's own default.
  std::optional<double> claim_timeout_s = 8;

  /// Writes the config of `spec`; `everyone` lists the fleet (for ports).
  std::string writeConfig(const AgentSpec& spec, const std::vector<AgentSpec>& everyone) {
    std::ostringstream c;
    c << "agent = \"" << spec.id << "\"\n";
    if (!spec.map.empty()) c << "map = \"" << spec.map << "\"\n";  // none: a map from a ROS 2 topic
    c << "grid = " << spec.grid << "\ndiscovery_port = " << port(indexOf(spec.id, everyone))
      << "\nbandwidth_kbps = " << spec.bandwidth_kbps << "\noutput_dir = \"" << (dir_ / ("out-" + spec.id))
      << "\"\nrequest_interval_s = 1\n";
    if (claim_timeout_s) c << "claim_timeout_s = " << *claim_timeout_s << "\n";
    c << spec.extra;
    for (const auto& other : everyone) {
      if (other.id == spec.id) continue;
      if (!spec.peers.empty() && std::find(spec.peers.begin(), spec.peers.end(), other.id) == spec.peers.end())
        continue;
      c << "[[peer]]\nid = \"" << other.id << "\"\nhost = \"127.0.0.1\"\nport = " << port(indexOf(other.id, everyone))
        << "\n";
    }
    const std::string path = dir_ / (spec.id + ".toml");
    std::ofstream(path) << c.str();
    return path;
  }

  /// Starts `spec`'s daemon; `env` ("NAME=value") is added to its environment.
  void start(const AgentSpec& spec, const std::vector<AgentSpec>& everyone, const std::vector<std::string>& env = {}) {
    const std::string config = writeConfig(spec, everyone);
    const std::string log = dir_ / (spec.id + ".log");
    const pid_t pid = fork();
    if (pid == 0) {
      FILE* f = freopen(log.c_str(), "a", stderr);
      (void)f;
      for (const auto& e : env) putenv(const_cast<char*>(e.c_str()));
      execl(TOMOMAPD_BIN, TOMOMAPD_BIN, "--config", config.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    pids_[spec.id] = pid;
  }

  /// Sends `sig`; for SIGKILL also reaps the process.
  void kill(const std::string& id, int sig) {
    const auto it = pids_.find(id);
    if (it == pids_.end()) return;
    ::kill(it->second, sig);
    if (sig == SIGKILL) {
      waitpid(it->second, nullptr, 0);
      pids_.erase(it);
    }
  }

  /// Waits for `id` to exit; returns its exit code, or nullopt after `timeout`.
  std::optional<int> waitExit(const std::string& id, std::chrono::milliseconds timeout) {
    const auto it = pids_.find(id);
    if (it == pids_.end()) return std::nullopt;
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < until) {
      int status = 0;
      if (waitpid(it->second, &status, WNOHANG) == it->second) {
        pids_.erase(it);
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return std::nullopt;
  }

  nlohmann::json readJson(const std::string& id, const std::string& file) const {
    std::ifstream in(dir_ / ("out-" + id + "/" + file));
    if (!in) return {};
    try {
      return nlohmann::json::parse(in);
    } catch (...) {
      return {};
    }
  }

  /// The transforms `id` has stored, by "target<-source".
  std::map<std::string, nlohmann::json> transforms(const std::string& id) const {
    std::map<std::string, nlohmann::json> out;
    const auto j = readJson(id, "transforms.json");
    if (j.contains("transforms"))
      for (const auto& t : j["transforms"])
        out[t["target"].get<std::string>() + "<-" + t["source"].get<std::string>()] = t;
    return out;
  }

  /// Polls until every agent in `ids` stores `pairs` transforms, or `timeout`.
  bool waitForTransforms(const std::vector<std::string>& ids, size_t pairs, std::chrono::seconds timeout) const {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < until) {
      bool all = true;
      for (const auto& id : ids) all = all && transforms(id).size() >= pairs;
      if (all) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return false;
  }

  pid_t pid(const std::string& id) const { return pids_.at(id); }

  /// Polls `pred` until it holds or `timeout` passes.
  template <typename Pred>
  static bool waitFor(Pred pred, std::chrono::milliseconds timeout) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < until) {
      if (pred()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return pred();
  }

  std::string log(const std::string& id) const { return readText(dir_ / (id + ".log")); }

 private:
  static size_t indexOf(const std::string& id, const std::vector<AgentSpec>& everyone) {
    for (size_t i = 0; i < everyone.size(); ++i)
      if (everyone[i].id == id) return i;
    return everyone.size();
  }

  TempDir& dir_;
  uint16_t base_port_;
  std::map<std::string, pid_t> pids_;
};

/// T_target_source of one transforms.json entry.
inline Pose4 poseOf(const nlohmann::json& t) {
  const auto& T = t["T_target_source"];
  return {T["x"].get<double>(), T["y"].get<double>(), T["z"].get<double>(), T["yaw"].get<double>()};
}

/// Matches computed across the agents `ids`, from each daemon's status.json.
inline int matchesComputed(const Fleet& fleet, const std::vector<std::string>& ids) {
  int n = 0;
  for (const auto& id : ids) n += fleet.readJson(id, "status.json").value("matches_computed", 0);
  return n;
}

/// matchesComputed once it reaches `expected` (or `timeout` passes): an agent
/// writes status.json just after transforms.json, so right after a test saw
/// the transforms the count may still be one write behind.
inline int matchesComputedReaching(const Fleet& fleet, const std::vector<std::string>& ids, int expected,
                                   std::chrono::seconds timeout = std::chrono::seconds(30)) {
  Fleet::waitFor([&] { return matchesComputed(fleet, ids) >= expected; }, timeout);
  return matchesComputed(fleet, ids);
}

/// How long systemd waits for tomomapd to stop after SIGTERM before killing
/// it (TimeoutStopSec in the shipped unit): the deadline a stop must meet.
inline std::chrono::milliseconds stopTimeout() {
  std::ifstream unit(TOMOMAP_SOURCE_DIR "/daemon/tomomapd.service.in");
  const std::string key = "TimeoutStopSec=";
  for (std::string line; std::getline(unit, line);)
    if (line.rfind(key, 0) == 0) return std::chrono::seconds(std::stoi(line.substr(key.size())));
  ADD_FAILURE() << "no " << key << " in daemon/tomomapd.service.in";
  return std::chrono::seconds(10);
}

/// Waits until `source`'s map version is no longer `before` and every agent
/// of `ids` holds `pair` agreed for the new one; returns that version (empty
/// if not within `timeout`).
inline std::string waitForReagreement(const Fleet& fleet, const std::vector<std::string>& ids, const std::string& pair,
                                      const std::string& source, const std::string& before,
                                      std::chrono::seconds timeout) {
  std::string now;
  const bool agreed = Fleet::waitFor(
      [&] {
        now = fleet.readJson(source, "status.json")["map"].value("version", "");
        if (now.empty() || now == before) return false;
        for (const auto& id : ids) {
          const auto t = fleet.transforms(id);
          if (!t.count(pair) || t.at(pair)["source_version"] != now) return false;
        }
        return true;
      },
      timeout);
  return agreed ? now : std::string();
}

/// Stops every agent with SIGTERM and checks each leaves cleanly within the
/// unit's stop timeout.
inline void stopAll(Fleet& fleet, const std::vector<std::string>& ids) {
  for (const auto& id : ids) fleet.kill(id, SIGTERM);
  for (const auto& id : ids) {
    const auto code = fleet.waitExit(id, stopTimeout());
    ASSERT_TRUE(code.has_value()) << id << " did not stop within TimeoutStopSec\n" << fleet.log(id);
    EXPECT_EQ(*code, 0) << fleet.log(id);
    EXPECT_NE(fleet.log(id).find("stopped"), std::string::npos);
  }
}

}  // namespace tomomap::test
