#pragma once
// One tomomapd: the event loop and the wiring between the network, this
// agent's own map (MapSender), the peers' maps (PeerMaps), who computes which
// pair (PairBoard) and the matching thread (MatchWorker). All state lives on
// the thread that calls run(); DDS callbacks only queue work for it.
#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>

#include "clock.hpp"
#include "config.hpp"
#include "fleet_map_builder.hpp"
#include "fleet_outputs.hpp"
#include "log.hpp"
#include "map_sender.hpp"
#include "map_watch.hpp"
#include "match_worker.hpp"
#include "notify.hpp"
#include "pair_board.hpp"
#include "peer_maps.hpp"
#include "rejection_log.hpp"
#include "results/fleet_frame.hpp"
#include "transport/bus.hpp"
#include "transport/ros2_node.hpp"

namespace tomomap::daemon {

/// What the signal thread tells the agent: set there, acted on in the loop.
struct Signals {
  std::atomic<bool> stop{false};
  std::atomic<bool> reload{false};  ///< SIGHUP: read the config and the map again
};

/// This agent's own map, described and cut into samples.
struct OwnMap {
  std::shared_ptr<const MapFeatures> features;
  transport::MapOffer offer;
  size_t cells = 0;      ///< voxel-filtered points
  size_t nonfinite = 0;  ///< points with NaN or infinite coordinates, dropped
  std::string note;      ///< how the file was read, when a user should know (loadMap)
  double seconds = 0;    ///< time taken to describe it
  StageTimings stages;   ///< of which reading (load), voxel filter, slicing and ORB (features)
  double encoding = 0;   ///< of which the offer: the slices encoded for the wire, the version [s]
  std::string frame_id;  ///< the map message's frame (map from a topic); empty for a file
};

/// Where the config says the map comes from: its file, or "ROS 2 topic X".
std::string mapSource(const Config& config);

/// This agent's map as it was last described and offered: what an update of
/// it keeps (slices the change did not touch are not described or encoded again).
struct Described {
  std::shared_ptr<const MapFeatures> features;
  std::shared_ptr<const transport::MapOffer> offer;
};

/// Loads, describes and encodes the map the config names (its file). Throws
/// InputError for an unreadable map. Pure work: safe to run on any thread.
OwnMap describeOwnMap(const Config& config, const Described& before = {});
/// The same for a map that arrived on the [ros2] map_topic.
OwnMap describeOwnMap(const Config& config, const transport::MapMessage& message, const Described& before = {});

/// The claim timings the config sets.
inline BoardTimings boardTimings(const Config& c) {
  BoardTimings t;
  t.claim_timeout = fromSeconds(c.claim_timeout_s);
  return t;
}

class Agent {
 public:
  Agent(Config config, Log& log);

  /// Loads and describes the map, joins the network and serves until `stop`.
  /// Returns the process exit code.
  int run(Signals& signals);

 private:
  struct Counters {
    size_t unknown_agent = 0, rejected = 0, matches_computed = 0;
    size_t impostors = 0;             ///< samples in another agent's name than their sender's
    size_t refused_participants = 0;  ///< participants that speak for no agent
  };

  // ---- lifecycle (agent_lifecycle.cpp)
  void post(std::function<void()> work);
  void joinNetwork();
  /// Starts describing the map again on a helper thread once its file has
  /// been quiet for a moment, and installs the result when it is a new version.
  void followMapFile();
  /// SIGHUP: a new config (kept only if it reads and is valid) and the map.
  void reload();
  /// One turn of the loop once every received event is applied.
  void tick(Clock::time_point& last_announce);

  // ---- what arrives (agent.cpp)
  /// Makes `own` the map this agent offers; announces it when on the network.
  void installOwnMap(OwnMap own);
  /// Whether `agent` is this agent or a configured peer; counts the others.
  bool known(const std::string& agent, const char* what);
  /// known(), and notes that `sender` spoke.
  bool fromKnown(const std::string& sender, const char* what);
  void reject(const std::string& from, const transport::Rejection& why);
  void onAnnouncement(wire::MapAnnouncement&& a);
  void onSlice(wire::SliceFeatures&& s, size_t bytes, uint64_t sequence);
  void onRequest(wire::ChunkRequest&& r);
  void onClaim(wire::MatchClaim&& c);
  void onEstimate(wire::TransformEstimate&& e);
  void onPeer(const std::string& agent, bool alive);
  void onImpostor(const std::string& claimed, const std::string& sender);
  void onRefused(const std::string& participant, const std::string& why);

  // ---- what this agent does
  void requestMissing();
  void claimAndCompute();
  void finishCompute();
  /// Whether a peer's announced grid is ours; says once per peer and grid when not.
  bool sameGrid(const std::string& owner, double grid);
  /// Says so when a stored answer did not replace the pair's reliable one.
  void logIfKept(const PairKey& pair);
  std::shared_ptr<const MapFeatures> featuresOf(const std::string& agent) const;

  // ---- what it tells its operator (agent_status.cpp) and ROS 2 (agent_ros2.cpp)
  /// The agreed transforms changed: the fleet's outputs follow (FleetOutputs:
  /// the frame, transforms.json and frame.json, /tf_static), then status.json.
  void agreedChanged();
  /// Writes status.json; first retries an output write that failed before
  /// (`retry_outputs`: each status write retries it until it succeeds).
  void writeStatus(bool retry_outputs = true);
  /// At start: the transforms this agent stored before (transforms.json).
  void restoreTransforms();
  /// Creates the ROS 2 node when [ros2] asks for it (a failure is logged:
  /// the fleet works on without it).
  void startRos2();
  /// Publishes `status` (status.json's content) on /diagnostics, once per
  /// kDiagnosticsPeriod at most.
  void publishDiagnostics(const nlohmann::json& status);
  // ---- the fleet's map (agent_fleet_map.cpp)
  /// What the fleet's map is made of now: every placed map held here.
  FleetMapJob fleetMapJob() const;
  /// Takes a finished build in, and starts the next when its parts changed
  /// and have stayed so for `[fleet_map] interval_s` (or have kept changing
  /// for six of them), and the last started an interval ago.
  void followFleetMap();
  /// Hands a build to ROS 2 when there is a node (what went wrong goes to its status).
  void publishFleetMap(const FleetMapBuilt& built);
  /// Builds it anew at the next chance even if nothing it is made of changed
  /// (a new ROS 2 node, a new config).
  void refreshFleetMap() { fleet_map_parts_.clear(); }
  /// status.json's `fleet_map`: the last build, and whether it is current.
  nlohmann::json fleetMapStatus() const;

  /// One line of progress for systemd's STATUS= (and `systemctl status`).
  std::string statusLine() const;

  Config config_;
  Log& log_;
  std::unique_ptr<transport::Bus> bus_;
  FleetOutputs outputs_{log_};  ///< the fleet's frame, transforms.json and frame.json, /tf_static
  std::unique_ptr<transport::Ros2Node> ros2_;
  std::optional<Clock::time_point> diagnostics_published_;
  /// The latest map message from [ros2] map_topic not yet described; one at a
  /// time: a SLAM package may publish its map with every scan.
  std::shared_ptr<const transport::MapMessage> map_message_;
  std::string map_frame_id_;  ///< the frame of the map offered, when it came from a topic
  transport::BusHandlers handlers_;
  Notifier notifier_;
  std::unique_ptr<MapWatch> watch_;
  std::optional<Clock::time_point> map_touched_;  ///< last change seen and not yet described
  std::future<OwnMap> describing_;
  uint64_t map_updated_ms_ = 0;
  std::string map_refused_;  ///< why the map file's latest content is not offered; empty when it is
  std::mutex queue_mutex_;
  std::condition_variable queue_cv_;
  std::deque<std::function<void()>> queue_;

  std::shared_ptr<const MapFeatures> own_features_;  ///< null until the map file first exists and is usable
  /// Whether this agent offers a map yet (at boot the file may not exist).
  bool offering() const { return own_features_ != nullptr; }
  /// What the map on offer lends its next version.
  Described described() const;
  /// What the status says while nothing is offered.
  std::string waitingText() const;
  MapSender sender_;
  PeerMaps peers_;
  PairBoard board_;
  MatchWorker worker_;
  Counters counters_;
  std::map<std::string, std::string> other_grid_;  ///< peers whose map uses another grid, and what to say
  Clock::time_point last_status_{};
  bool status_unwritten_ = false;  ///< status.json's last write failed
  RejectionLog rejections_;        ///< warnings for rejected samples, bounded per sender
  bool reannounce_ =
      false;  ///< a peer asked for our announcement: announce again (tick, once for peers that ask together)
  Clock::time_point started_ = Clock::now();
  FleetMapBuilder fleet_map_{[this] { queue_cv_.notify_one(); }};
  std::vector<FleetMapPart> fleet_map_parts_;  ///< what the last build started was made of
  std::vector<FleetMapPart> fleet_map_seen_;   ///< what the map is made of now, as last looked at
  Clock::time_point fleet_map_seen_since_{};   ///< since when
  std::optional<Clock::time_point> fleet_map_started_;
  nlohmann::json fleet_map_status_;  ///< the last build's, for status.json; null before the first
};

}  // namespace tomomap::daemon
