#pragma once
// One tomomapd: its own map's offer, every peer's map as it arrives, claims,
// matching and the agreed transforms. All state lives on the thread that calls
// run(); DDS callbacks only queue work for it, and matching runs on a worker.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include "config.hpp"
#include "log.hpp"
#include "map_watch.hpp"
#include "notify.hpp"
#include "transport/bus.hpp"
#include "transport/slice_codec.hpp"

namespace tomomap::daemon {

using Clock = std::chrono::steady_clock;

/// An ordered pair of agents: target < source by id.
using PairKey = std::pair<std::string, std::string>;

/// What the signal thread tells the agent: set there, acted on in the loop.
struct Signals {
  std::atomic<bool> stop{false};
  std::atomic<bool> reload{false};  ///< SIGHUP: read the config and the map again
};

/// This agent's own map, described and cut into samples.
struct OwnMap {
  std::shared_ptr<const MapFeatures> features;
  transport::MapOffer offer;
  size_t cells = 0;       ///< voxel-filtered points
  double seconds = 0;     ///< time taken to describe it
};

/// Loads, describes and encodes the map the config names. Throws InputError
/// for an unreadable map. Pure work: safe to run on any thread.
OwnMap describeOwnMap(const Config& config);

class Agent {
 public:
  Agent(Config config, Log& log);
  ~Agent();

  /// Loads and describes the map, joins the network and serves until `stop`.
  /// Returns the process exit code.
  int run(Signals& signals);

 private:
  struct PeerMap {
    std::optional<transport::Reassembler> incoming;  ///< the latest announced version
    std::shared_ptr<const MapFeatures> features;     ///< once complete
    Clock::time_point last_progress{}, last_request{};
    Clock::time_point requested{};  ///< when this version was first asked for: the transfer's start
    Clock::time_point first_slice{}, last_slice{};
    size_t bytes = 0, samples = 0;
    size_t reused = 0;  ///< slices kept from the previous version
  };
  /// A finished transfer of one version of a peer's map, for status.json.
  struct Transfer {
    uint64_t version = 0;
    size_t slices = 0, reused = 0, bytes = 0;
    double seconds = 0;
  };
  struct Claim {
    std::string claimer;
    uint64_t target_version = 0, source_version = 0;
    Clock::time_point seen;
  };
  struct Counters {
    size_t unknown_agent = 0, rejected = 0, bytes_sent = 0, samples_sent = 0, matches_computed = 0;
  };

  void post(std::function<void()> work);
  /// Makes `own` the map this agent offers; announces it when on the network.
  void installOwnMap(OwnMap own);
  /// Starts describing the map again on a helper thread once its file has
  /// been quiet for a moment, and installs the result when it is a new version.
  void followMapFile();
  /// SIGHUP: a new config (kept only if it reads and is valid) and the map.
  void reload();
  void joinNetwork();
  /// Notes that `sender` spoke; false (and counted) for an agent not in the config.
  bool fromKnown(const std::string& sender, const char* what);
  void onAnnouncement(wire::MapAnnouncement&& a);
  void onSlice(wire::SliceFeatures&& s, size_t bytes);
  /// Builds a peer's map once every slice is in, and records the transfer.
  void completeTransfer(const std::string& owner, PeerMap& p);
  void onRequest(wire::ChunkRequest&& r);
  void onClaim(wire::MatchClaim&& c);
  void onEstimate(wire::TransformEstimate&& e);
  void onPeer(const std::string& name, bool alive);
  bool known(const std::string& agent, const char* what);
  void reject(const std::string& from, const std::string& why);

  void pumpSends();
  void requestMissing(bool now = false);
  /// Transfer rate of a peer's map so far [kbit/s]: bytes over the flow-control
  /// periods they took (the first period's budget leaves at once, so the time
  /// from the first to the last sample is one period short).
  double rateKbps(const PeerMap& p) const;
  void claimAndCompute();
  void finishCompute();
  void persist(bool transforms_changed);
  /// One line of progress for systemd's STATUS= (and `systemctl status`).
  std::string statusLine() const;
  std::optional<uint64_t> versionOf(const std::string& agent) const;
  /// Whether `e` was computed for the maps' versions known now.
  bool isCurrent(const wire::TransformEstimate& e) const;
  std::shared_ptr<const MapFeatures> featuresOf(const std::string& agent) const;

  Config config_;
  Log& log_;
  std::unique_ptr<transport::Bus> bus_;
  transport::BusHandlers handlers_;
  Notifier notifier_;
  std::unique_ptr<MapWatch> watch_;
  std::optional<Clock::time_point> map_touched_;  ///< last change seen and not yet described
  std::future<OwnMap> describing_;
  uint64_t map_updated_ms_ = 0;
  std::mutex queue_mutex_;
  std::condition_variable queue_cv_;
  std::deque<std::function<void()>> queue_;

  std::shared_ptr<const MapFeatures> own_features_;
  transport::MapOffer offer_;
  std::deque<int> send_queue_;  ///< slices to send, in order
  std::set<int> queued_;
  size_t next_part_ = 0;        ///< part of send_queue_.front() to send next
  /// When the flow controller will have sent everything written so far, and
  /// when each slice's last copy leaves: a request for a slice still on its way
  /// is not a reason to send it again.
  Clock::time_point backlog_until_{};
  std::map<int, Clock::time_point> leaves_at_;

  std::map<std::string, PeerMap> peers_;
  std::map<PairKey, Claim> claims_;
  std::map<PairKey, Clock::time_point> own_claims_;  ///< pairs we claimed, and when
  std::map<PairKey, wire::TransformEstimate> results_;
  std::set<std::string> alive_;  ///< peers whose participant is discovered
  std::map<std::string, uint64_t> last_seen_ms_;  ///< wall time of each peer's last sample
  std::map<std::string, std::deque<Transfer>> transfers_;  ///< finished transfers per peer, latest last
  Counters counters_;

  std::thread worker_;
  std::atomic<bool> worker_done_{false};
  std::optional<PairKey> computing_;
  wire::TransformEstimate computed_;
  Clock::time_point last_status_{};
  Clock::time_point started_ = Clock::now();
};

}  // namespace tomomap::daemon
