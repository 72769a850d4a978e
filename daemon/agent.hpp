#pragma once
// One tomomapd: its own map's offer, every peer's map as it arrives, claims,
// matching and the agreed transforms. All state lives on the thread that calls
// run(); DDS callbacks only queue work for it, and matching runs on a worker.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include "config.hpp"
#include "log.hpp"
#include "transport/bus.hpp"
#include "transport/slice_codec.hpp"

namespace tomomap::daemon {

using Clock = std::chrono::steady_clock;

/// An ordered pair of agents: target < source by id.
using PairKey = std::pair<std::string, std::string>;

class Agent {
 public:
  Agent(Config config, Log& log);
  ~Agent();

  /// Loads and describes the map, joins the network and serves until `stop`.
  /// Returns the process exit code.
  int run(const std::atomic<bool>& stop);

 private:
  struct PeerMap {
    std::optional<transport::Reassembler> incoming;  ///< the latest announced version
    std::shared_ptr<const MapFeatures> features;     ///< once complete
    Clock::time_point last_progress{}, last_request{};
    Clock::time_point requested{};  ///< when this version was first asked for: the transfer's start
    Clock::time_point first_slice{}, last_slice{};
    size_t bytes = 0, samples = 0;
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
  void describeOwnMap();
  void onAnnouncement(wire::MapAnnouncement&& a);
  void onSlice(wire::SliceFeatures&& s, size_t bytes);
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
  std::optional<uint64_t> versionOf(const std::string& agent) const;
  std::shared_ptr<const MapFeatures> featuresOf(const std::string& agent) const;

  Config config_;
  Log& log_;
  std::unique_ptr<transport::Bus> bus_;
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
  Counters counters_;

  std::thread worker_;
  std::atomic<bool> worker_done_{false};
  std::optional<PairKey> computing_;
  wire::TransformEstimate computed_;
  Clock::time_point last_status_{};
  Clock::time_point started_ = Clock::now();
};

}  // namespace tomomap::daemon
