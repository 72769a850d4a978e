// The agent's life: start, the event loop, following the map file, SIGHUP
// reloads and a clean stop.
#include <filesystem>

#include "agent.hpp"
#include "core/text.hpp"
#include "settings.hpp"

namespace tomomap::daemon {

namespace fs = std::filesystem;

namespace {

constexpr auto kTick = std::chrono::milliseconds(50);
constexpr auto kReannounce = std::chrono::seconds(30);
constexpr auto kReannounceGap = std::chrono::seconds(3);  ///< between announcements peers asked for
constexpr auto kStatusEvery = std::chrono::seconds(1);
/// A map file must be quiet this long before it is read: writers that open,
/// write and close it several times are done by then.
constexpr auto kMapSettle = std::chrono::milliseconds(1000);

/// Whether the network needs no rejoin: no setting that asks for one
/// changed (settings.hpp declares which do), nor the peers, nor the security
/// files' contents, nor an injected loss.
bool sameNetwork(const Config& a, const Config& b) {
  if (!changed(a, b, Reload::Rejoin).empty() || a.transport.security.contents != b.transport.security.contents ||
      a.transport.test_drop_percent != b.transport.test_drop_percent ||
      a.transport.peers.size() != b.transport.peers.size())
    return false;
  for (size_t i = 0; i < a.transport.peers.size(); ++i) {
    const auto &p = a.transport.peers[i], &q = b.transport.peers[i];
    if (p.id != q.id || p.host != q.host || p.port != q.port) return false;
  }
  return true;
}

bool createOutputDir(const std::string& dir, Log& log) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) log.error(dir + ": cannot create the output directory: " + ec.message());
  return !ec;
}

}  // namespace

void Agent::joinNetwork() {
  bus_ = std::make_unique<transport::Bus>(config_.transport, handlers_);
  if (offering()) bus_->publish(sender_.offer().announcement);
}

std::string Agent::waitingText() const {
  return "waiting for map " + mapSource(config_) + (map_refused_.empty() ? "" : " (its content: " + map_refused_ + ")");
}

void Agent::followMapFile() {
  if (watch_ && watch_->changed()) map_touched_ = Clock::now();
  if (describing_.valid()) {
    if (describing_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
    try {
      OwnMap own = describing_.get();
      map_refused_.clear();
      if (own.offer.announcement.version() == sender_.version())
        log_.info("map " + std::string(config_.ros2.map_topic.empty() ? "file rewritten" : "published again") +
                  " with the same content: version " + versionText(sender_.version()) + " stays");
      else
        installOwnMap(std::move(own));
    } catch (const std::exception& e) {
      // Typically a file caught half-written: its next write brings us back.
      map_refused_ = e.what();
      log_.warning(std::string("map changed but cannot be used (") + e.what() + "); " +
                   (offering() ? "still offering version " + versionText(sender_.version()) : "offering no map yet"));
    }
    return;
  }
  if (!map_touched_ || Clock::now() - *map_touched_ < kMapSettle) return;
  map_touched_.reset();
  // On a helper thread: the loop keeps serving peers. It gets a copy of the
  // config (and of the message) and nothing of the agent's state.
  if (!config_.ros2.map_topic.empty()) {
    if (!map_message_) return;
    log_.info("map message on " + config_.ros2.map_topic + " (" + std::to_string(map_message_->data.size()) +
              " bytes): describing it");
    describing_ = std::async(std::launch::async, [config = config_, cloud = std::move(map_message_), before = described()] {
      return describeOwnMap(config, *cloud, before);
    });
    return;
  }
  log_.info("map file changed: describing it again");
  describing_ = std::async(std::launch::async,
                           [config = config_, before = described()] { return describeOwnMap(config, before); });
}

void Agent::reload() {
  notifier_.reloading();
  log_.info("SIGHUP: reading " + config_.file + " again");
  Config next;
  try {
    next = loadConfig(config_.file);
    if (next.agent() != config_.agent())
      throw InputError(config_.file + ": key 'agent': cannot change from '" + config_.agent() + "' to '" +
                       next.agent() + "' while running; restart the service");
  } catch (const InputError& e) {
    log_.error(std::string("reload refused, the running configuration stays: ") + e.what());
    notifier_.ready();
    return;
  }
  if (!createOutputDir(next.output_dir, log_)) {
    notifier_.ready();
    return;
  }
  // Decided now: a failed join below moves `previous` back into config_.
  const bool ros2_changed =
      !changed(next, config_, Reload::RestartsRos2).empty() || next.treeRoot() != config_.treeRoot();
  Config previous = std::move(config_);
  config_ = std::move(next);
  log_.setThreshold(config_.log_level);
  log_.info(describe(config_));
  sender_.setBudget(transport::streamKbps(config_.transport), fromSeconds(config_.request_interval_s));
  peers_.setMemoryBudget(peerMemoryBytes(config_));
  board_.setTimings(boardTimings(config_));
  board_.setFleet(config_.peerIds());
  if (!sameNetwork(previous, config_)) {
    log_.info("network settings changed: leaving and joining again");
    bus_.reset();
    peers_.clearAlive();
    board_.leftNetwork();
    const auto keep = [this](const std::string& id) { return config_.isPeer(id); };
    peers_.retain(keep);
    board_.retainMaps(keep);
    try {
      joinNetwork();
    } catch (const std::exception& e) {
      log_.error(std::string("cannot join with the new settings (") + e.what() + "); back to the previous ones");
      config_ = std::move(previous);
      log_.setThreshold(config_.log_level);
      board_.setFleet(config_.peerIds());
      joinNetwork();  // worked before; if not, the error ends the process and systemd restarts it
    }
  }
  if (ros2_changed) startRos2();
  refreshFleetMap();
  watch_ = config_.ros2.map_topic.empty() ? std::make_unique<MapWatch>(config_.map) : nullptr;
  map_touched_ = Clock::now() - kMapSettle;  // and read the map again now
  agreedChanged();
  notifier_.ready();
}

void Agent::tick(Clock::time_point& last_announce) {
  finishCompute();
  followMapFile();
  const auto now = Clock::now();
  if (sender_.mayStart(bus_->sliceReaders(), peers_.aliveCount(), now))
    sender_.pump([this](const wire::SliceFeatures& x) { return bus_->publish(x); }, transport::Bus::serializedSize,
                 now);
  requestMissing();
  claimAndCompute();
  followFleetMap();
  for (const auto& line : rejections_.due(now)) log_.warning(line);
  // Repairs a lost or missed announcement: when a peer asked for it (once
  // for peers that ask together, since each copy reaches every receiver),
  // and every kReannounce. Not while every live peer has shown it holds it (it
  // asked for our slices): some 2 kB a receiver with a hundred slices.
  const bool due = now - last_announce > kReannounce || (reannounce_ && now - last_announce > kReannounceGap);
  if (due && offering()) {
    reannounce_ = false;
    last_announce = now;
    if (!sender_.informed(peers_.alive())) bus_->publish(sender_.offer().announcement);
  }
  if (now - last_status_ > kStatusEvery) {
    writeStatus();
    notifier_.status(statusLine());
    last_status_ = now;
  }
}

int Agent::run(Signals& signals) {
  log_.info(describe(config_));
  if (!createOutputDir(config_.output_dir, log_)) return 2;
  restoreTransforms();
  // At boot the map may not be written yet: the agent joins and waits for it
  // (the folder is watched below). A map that exists but cannot be used is a
  // mistake to fix, not to wait out.
  if (!config_.ros2.map_topic.empty()) {
    log_.info("the map comes from ROS 2 topic " + config_.ros2.map_topic + ": matching starts with its first message");
  } else if (fs::exists(config_.map)) {
    try {
      installOwnMap(describeOwnMap(config_));
    } catch (const InputError& e) {
      log_.error(e.what());
      return 2;
    }
  } else {
    log_.warning(config_.map + " does not exist yet: waiting for it (matching starts when it appears)");
  }
  auto& h = handlers_;
  h.announcement = [this](wire::MapAnnouncement&& a) {
    post([this, a = std::move(a)]() mutable { onAnnouncement(std::move(a)); });
  };
  h.slice = [this](wire::SliceFeatures&& s, size_t bytes, uint64_t sequence) {
    post([this, s = std::move(s), bytes, sequence]() mutable { onSlice(std::move(s), bytes, sequence); });
  };
  h.request = [this](wire::ChunkRequest&& r) { post([this, r = std::move(r)]() mutable { onRequest(std::move(r)); }); };
  h.claim = [this](wire::MatchClaim&& c) { post([this, c = std::move(c)]() mutable { onClaim(std::move(c)); }); };
  h.estimate = [this](wire::TransformEstimate&& e) {
    post([this, e = std::move(e)]() mutable { onEstimate(std::move(e)); });
  };
  h.peer = [this](const std::string& agent, bool alive) { post([this, agent, alive] { onPeer(agent, alive); }); };
  h.refused = [this](const std::string& who, const std::string& why) {
    post([this, who, why] { onRefused(who, why); });
  };
  h.impostor = [this](const std::string& claimed, const std::string& sender) {
    post([this, claimed, sender] { onImpostor(claimed, sender); });
  };
  try {
    joinNetwork();
  } catch (const std::exception& e) {
    log_.error(e.what());
    return 2;
  }
  startRos2();
  if (!config_.ros2.map_topic.empty() && !ros2_) {
    log_.error("cannot read the map from ROS 2 topic " + config_.ros2.map_topic + " without a ROS 2 node");
    return 2;
  }
  agreedChanged();
  if (config_.ros2.map_topic.empty()) watch_ = std::make_unique<MapWatch>(config_.map);
  if (watch_ && !watch_->active())
    log_.warning("cannot watch the folder of " + config_.map + " for changes: send SIGHUP after updating the map");
  // The log line first: whoever acts on READY=1 (a test, an operator) finds it.
  const std::string peers = std::to_string(config_.transport.peers.size()) + " peers";
  log_.info(offering() ? "ready: announced version " + versionText(sender_.version()) + " to " + peers
                       : "ready: joined " + peers + "; " + waitingText());
  notifier_.ready();
  notifier_.status(statusLine());  // says what a waiting agent waits for

  auto last_announce = Clock::now();
  while (!signals.stop) {
    notifier_.tick();
    if (signals.reload.exchange(false)) reload();
    std::deque<std::function<void()>> work;
    {
      std::unique_lock<std::mutex> lock(queue_mutex_);
      queue_cv_.wait_for(lock, kTick, [this] { return !queue_.empty() || worker_.ready() || fleet_map_.ready(); });
      work.swap(queue_);
    }
    // A stop is not held up by a long batch (a received map's slices under
    // load): what is left undone is asked for again after a restart.
    for (auto& w : work) {
      if (signals.stop) break;
      w();
    }
    if (signals.stop) break;
    {
      // Decide on claims only with every received event applied: work above
      // may have taken long (ORB on a received map) while claims arrived.
      std::lock_guard<std::mutex> lock(queue_mutex_);
      if (!queue_.empty()) continue;
    }
    tick(last_announce);
  }
  notifier_.stopping();
  log_.info("stopping");
  agreedChanged();
  // A match in progress is abandoned: the result would be recomputed by the
  // fleet. Leave without waiting for it; everything else is flushed.
  worker_.abandon();
  bus_.reset();
  log_.info("stopped");
  return 0;
}

}  // namespace tomomap::daemon
