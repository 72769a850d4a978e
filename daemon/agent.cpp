#include "agent.hpp"

#include "core/map_check.hpp"
#include "core/text.hpp"
#include "io/map_io.hpp"
#include "io/octomap_io.hpp"
#include "io/point_cloud2.hpp"
#include "transport/estimate_wire.hpp"

namespace tomomap::daemon {

Agent::Agent(Config config, Log& log)
    : config_(std::move(config)),
      log_(log),
      sender_(transport::streamKbps(config_.transport), fromSeconds(config_.request_interval_s)),
      peers_(config_.agent(), log, peerMemoryBytes(config_)),
      board_(config_.agent(), boardTimings(config_)),
      worker_([this] { queue_cv_.notify_one(); }) {
  board_.setFleet(config_.peerIds());
}

void Agent::post(std::function<void()> work) {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    queue_.push_back(std::move(work));
  }
  queue_cv_.notify_one();
}

namespace {

std::string tiltText(const MapFeatures& f) {
  if (!f.tilt.measured) return "tilt not measurable (too few flat surfaces)";
  return std::string(f.leveled ? "levelled: it leaned " : "tilt ") + leanText(f.tilt);
}

}  // namespace

std::string mapSource(const Config& config) {
  return config.ros2.map_topic.empty() ? config.map : "ROS 2 topic " + config.ros2.map_topic;
}

namespace {

/// Describes and encodes the map `load` reads into `own`'s counts, on
/// `before`'s cubes, raster and slices where they still hold.
OwnMap describeLoaded(const Config& config, OwnMap own, const std::function<Points(OwnMap&)>& load,
                      const Described& before) {
  const auto t0 = Clock::now();
  const bool alike = before.features && before.offer && before.features->grid == config.match.grid &&
                     transport::featureParamsOf(before.offer->announcement) == config.match.features;
  auto features = [&] {
    const Points map = load(own);  // dropped once described
    const auto loaded = Clock::now();
    auto described = std::make_shared<MapFeatures>(describeMap(map, config.match, &own.stages, &own.cells,
                                                               alike ? before.features.get() : nullptr, config.map_up));
    own.stages.load = seconds(loaded - t0);
    return described;
  }();
  // Peers would match slanted slices: offered nowhere, refused here.
  if (const auto why = tiltRefusal(*features, "own", config.match)) throw InputError(mapSource(config) + ": " + *why);
  const auto encoding = Clock::now();
  std::optional<transport::EarlierOffer> earlier;
  if (alike) earlier.emplace(transport::EarlierOffer{*before.features, *before.offer});
  own.offer = transport::makeOffer(
      config.agent(), *features, config.match.features, binaryPcdBytes(own.cells),
      transport::maxSampleBytes(config.transport.bandwidth_kbps, config.transport.security.enabled()),
      config.match.threads, earlier ? &*earlier : nullptr);
  own.features = std::move(features);
  own.encoding = seconds(Clock::now() - encoding);
  own.seconds = seconds(Clock::now() - t0);
  return own;
}

}  // namespace

OwnMap describeOwnMap(const Config& config, const Described& before) {
  return describeLoaded(
      config, {}, [&](OwnMap& own) { return loadMap(config.map, &own.nonfinite, &own.note); }, before);
}

Described Agent::described() const {
  if (!offering()) return {};
  return {own_features_, std::make_shared<const transport::MapOffer>(sender_.offer())};
}

OwnMap describeOwnMap(const Config& config, const transport::MapMessage& message, const Described& before) {
  OwnMap own;
  own.frame_id = message.frame_id;
  return describeLoaded(
      config, std::move(own),
      [&](OwnMap& o) {
        Points points;
        try {
          if (const auto& tree = message.octomap)
            points = octomapFromMessage(tree->binary, tree->id, tree->resolution, message.data);
          else
            points = pointsFromCloud2(message.layout, message.data.data(), message.data.size(), &o.nonfinite);
        } catch (const InputError& e) {
          throw InputError(mapSource(config) + ": " + e.what());
        }
        validateMap(points, mapSource(config));  // as a map file is (loadMap): an empty or tiny map is refused
        return points;
      },
      before);
}

void Agent::installOwnMap(OwnMap own) {
  if (!own.note.empty()) log_.info(own.note);
  const std::string source = mapSource(config_);
  if (own.nonfinite > 0)
    log_.warning(source + ": dropped " + std::to_string(own.nonfinite) + " points with NaN or infinite coordinates");
  if (own.features->occupancy.stray > 0)
    log_.warning(source + ": left out " + std::to_string(own.features->occupancy.stray) +
                 " stray voxels far from the rest of the map");
  map_frame_id_ = own.frame_id;
  const bool update = own_features_ != nullptr;
  const uint64_t before = sender_.version();
  sender_.setOffer(std::move(own.offer));
  own_features_ = std::move(own.features);
  map_updated_ms_ = wallMs();
  board_.ownMap(sender_.version());
  const auto& offer = sender_.offer();
  size_t as_cells = 0;
  for (const auto& [k, samples] : offer.samples)
    as_cells += samples.front().encoding() == wire::SliceEncoding::OCCUPANCY;
  const auto& a = offer.announcement;
  // An update on the previous version's raster: ORB and encoding only where it changed.
  const int occupied = own_features_->occupancy.occupiedSlices();
  const std::string anew = update ? "; ORB on " + std::to_string(occupied - own_features_->kept_slices) + " of " +
                                        std::to_string(occupied) + " slices, " + std::to_string(offer.encoded_slices) +
                                        " of " + std::to_string(a.slices().size()) + " encoded, the rest unchanged"
                                  : "";
  log_.info(
      std::string(update ? "map updated: " : "map ") + source +
      (own.frame_id.empty() ? "" : " (frame " + own.frame_id + ")") + ": " + std::to_string(own.cells) +
      " cells at g " + fixed(config_.match.grid, 3) + " m, " + std::to_string(a.slices().size()) +
      " descriptive slices (" + std::to_string(as_cells) + " sent as occupancy, the rest as features), " +
      std::to_string(own_features_->featureCount()) + " features; version " + versionText(a.version()) +
      (update ? " (was " + versionText(before) + ")" : "") + "; payload " + std::to_string(offer.payload_bytes) +
      " bytes = " + fixed(100.0 * static_cast<double>(offer.payload_bytes) / static_cast<double>(a.raw_bytes()), 1) +
      " % of the voxel-filtered map's binary PCD (" + std::to_string(a.raw_bytes()) + " bytes); " +
      tiltText(*own_features_) + "; described in " + fixed(own.seconds, 2) + " s (read " + fixed(own.stages.load, 2) +
      ", voxel filter " + fixed(own.stages.voxel, 2) + ", slices " + fixed(own.stages.slicing, 2) + ", ORB " +
      fixed(own.stages.features, 2) + ", encoding " + fixed(own.encoding, 2) + anew + ")");
  if (bus_) {
    bus_->publish(a);
    reannounce_ = false;  // every peer that asked gets this one
    writeStatus();
  }
}

bool Agent::known(const std::string& agent, const char* what) {
  if (config_.inFleet(agent)) return true;
  ++counters_.unknown_agent;
  log_.debug(std::string("dropped ") + what + " from unknown agent '" + agent + "'");
  return false;
}

bool Agent::fromKnown(const std::string& sender, const char* what) {
  if (!known(sender, what)) return false;
  peers_.seen(sender, wallMs());  // callers have set aside our own samples
  return true;
}

void Agent::onImpostor(const std::string& claimed, const std::string& sender) {
  ++counters_.impostors;
  const std::string from = sender.empty() ? "a participant that speaks for no agent" : sender;
  if (auto line = rejections_.note(from, "a sample in the name of '" + claimed + "' (dropped)", Clock::now()))
    log_.warning(*line);
}

void Agent::onRefused(const std::string& participant, const std::string& why) {
  ++counters_.refused_participants;
  // Keyed by name and reason: a stranger and an impostor can share a name
  // (tomomapd/alpha), and each deserves its line.
  if (auto line = rejections_.note(participant + " (" + why + ")", "its participant speaks for no agent", Clock::now()))
    log_.warning(*line);
}

void Agent::reject(const std::string& from, const transport::Rejection& why) {
  ++counters_.rejected;
  if (auto line = rejections_.note(from, why.text(), Clock::now())) log_.warning(*line);
}

std::shared_ptr<const MapFeatures> Agent::featuresOf(const std::string& agent) const {
  return agent == config_.agent() ? own_features_ : peers_.features(agent);
}

void Agent::onAnnouncement(wire::MapAnnouncement&& a) {
  const std::string owner = a.agent().to_string();
  if (owner == config_.agent() || !fromKnown(owner, "an announcement")) return;
  if (const auto why = transport::validate(a)) return reject(owner, why);
  if (const auto why = transport::fitsBudget(a, peers_.memoryBudget())) return reject(owner, why);
  if (!sameGrid(owner, a.grid())) return;
  const uint64_t version = a.version();
  const auto done = peers_.announce(std::move(a), Clock::now());
  if (!done.new_version) return;
  for (const auto& t : board_.mapAnnounced(owner, version)) {
    log_.info("agreed " + pairText(t.pair()) + " from " + t.computed_by + " (held until " + owner +
              "'s map was announced)");
    agreedChanged();
  }
  if (done.complete) {
    board_.mapHeld(owner);
    writeStatus();
  }
  if (done.request) bus_->publish(*done.request);
}

bool Agent::sameGrid(const std::string& owner, double grid) {
  // Slices of another grid cannot be matched with ours: nothing is requested,
  // rather than a whole map moved for a match that must fail.
  if (std::abs(grid - config_.match.grid) <= 1e-9) {
    if (other_grid_.erase(owner)) log_.info(owner + " now uses our grid (" + fixed(grid, 3) + " m)");
    return true;
  }
  const std::string why = "its map uses grid " + fixed(grid, 3) + " m, ours " + fixed(config_.match.grid, 3) +
                          " m: not requested, the pair cannot be matched (set the same grid on both)";
  if (other_grid_[owner] != why) {
    other_grid_[owner] = why;
    log_.warning(owner + ": " + why);
    writeStatus();
  }
  return false;
}

void Agent::onSlice(wire::SliceFeatures&& s, size_t bytes, uint64_t sequence) {
  const std::string owner = s.agent().to_string();
  if (owner == config_.agent() || !fromKnown(owner, "a slice")) return;
  const auto got = peers_.receive(s, bytes, sequence, Clock::now());
  if (got.rejection) return reject(owner, got.rejection);
  if (got.completed) board_.mapHeld(owner);
  // Status shows a transfer under way at once, not a second later.
  if (got.first || got.completed) writeStatus();
}

void Agent::onRequest(wire::ChunkRequest&& r) {
  if (r.requester().to_string() == config_.agent() || r.owner().to_string() != config_.agent()) return;
  if (!fromKnown(r.requester().to_string(), "a request")) return;
  // A request for another version (PeerMaps::kNoVersion: none) comes from a
  // peer that lacks our current announcement. While our map loads there is
  // none: the first goes to every peer when it is ready.
  if (offering() && r.version() != sender_.version()) reannounce_ = true;
  const size_t resent = sender_.resends();
  const size_t wanted = sender_.request(r.requester().to_string(), r.version(), r.slices(),
                                        std::chrono::milliseconds(r.stalled_ms()), Clock::now(), r.received_through());
  log_.debug(r.requester().to_string() + " asked for " + std::to_string(wanted) + " slices; " +
             std::to_string(sender_.queued()) + " queued, " + std::to_string(sender_.resends() - resent) +
             " of them again (their copies overdue or lost in its reader)");
}

void Agent::onClaim(wire::MatchClaim&& c) {
  const std::string claimer = c.claimer().to_string();
  if (claimer == config_.agent() || !fromKnown(claimer, "a claim")) return;
  const PairAt at{{c.target().to_string(), c.source().to_string()}, c.target_version(), c.source_version()};
  board_.claimSeen(claimer, at, Clock::now());
  log_.debug(claimer + " claims " + pairText(at.pair));
}

void Agent::onEstimate(wire::TransformEstimate&& e) {
  const std::string by = e.computed_by().to_string();
  if (by == config_.agent()) return;  // our own, stored already
  if (!known(e.target().to_string(), "an estimate") || !known(e.source().to_string(), "an estimate") ||
      !fromKnown(by, "an estimate"))
    return;
  AgreedTransform t;
  if (const auto why = transport::fromWire(e, t)) return reject(by, why);
  const std::string line = "agreed " + pairText(t.pair()) + " from " + by + ": x " + fixed(t.T_target_source.x, 3) +
                           " y " + fixed(t.T_target_source.y, 3) + " z " + fixed(t.T_target_source.z, 3) + " yaw " +
                           fixed(t.T_target_source.yaw, 4) +
                           (t.reliable ? "" : " (no reliable match: " + t.reason + ")");
  const PairKey pair = t.pair();
  if (board_.estimateSeen(std::move(t)) != PairBoard::Offer::Stored) return;
  log_.info(line);
  logIfKept(pair);
  agreedChanged();
}

void Agent::logIfKept(const PairKey& pair) {
  const PairStatus s = board_.status(pair, Clock::now());
  if (s.state == PairState::Kept)
    log_.warning(pairText(pair) + ": the current maps gave no reliable match (" + s.why +
                 "); the reliable transform agreed for their earlier versions stays");
}

void Agent::onPeer(const std::string& id, bool alive) {
  if (!config_.isPeer(id)) {
    if (id != config_.agent())
      log_.debug("participant of '" + id + "' is not in the config; its samples will be dropped");
    return;
  }
  if (alive) {
    if (peers_.setAlive(id, true)) log_.info("peer " + id + " is up");
    board_.agentUp(id);
    if (auto r = peers_.askNow(id, Clock::now())) bus_->publish(*r);  // what we asked it before was lost
    // Durability gives it our announcement, or it asks for it (PeerMaps::due):
    // Fast DDS misses a late reader now and then (eProsima/Fast-DDS#3822). A
    // peer that comes up again may have restarted without it.
    sender_.forget(id);
    // A late joiner gets what this agent computed, in case durability missed it.
    for (const auto* held : {&board_.results(), &board_.keptBeside()})
      for (const auto& [key, t] : *held)
        if (t.computed_by == config_.agent()) bus_->publish(transport::toWire(t));
  } else if (peers_.setAlive(id, false)) {
    log_.warning("peer " + id + " is gone");
    board_.agentGone(id);
  }
}

void Agent::requestMissing() {
  for (const auto& r : peers_.due(fromSeconds(config_.request_interval_s), Clock::now())) bus_->publish(r);
}

void Agent::claimAndCompute() {
  // The board knows when a match is running: then it only renews that claim.
  const bool renewing = board_.computing().has_value();
  const BoardStep step = board_.step(Clock::now());
  for (const PairAt& at : step.claims) {
    wire::MatchClaim c;
    c.target(at.pair.first);
    c.source(at.pair.second);
    c.target_version(at.target_version);
    c.source_version(at.source_version);
    c.claimer(config_.agent());
    c.claimed_at_ms(wallMs());
    bus_->publish(c);
    if (renewing)
      log_.debug("renewed the claim on " + pairText(at.pair));
    else
      log_.info("claimed " + pairText(at.pair));
  }
  for (const auto& y : step.yielded) log_.info("yielding " + y);
  if (!step.compute) return;
  const PairAt& at = *step.compute;
  worker_.start(at, featuresOf(at.pair.first), featuresOf(at.pair.second), config_.match, config_.agent());
  log_.info("computing " + pairText(at.pair));
}

void Agent::finishCompute() {
  if (!worker_.ready()) return;
  MatchWorker::Computed computed = worker_.take();
  AgreedTransform& t = computed.transform;
  ++counters_.matches_computed;
  if (t.reliable && pairText(t.pair()) == config_.faults.wrong_pair) {
    t.T_target_source = t.T_target_source * Pose4{1.5, 0, 0, radians(30)};
    log_.warning("test fault wrong_pair: " + config_.faults.wrong_pair + " published moved 1.5 m and 30 deg");
  }
  const Pose4& T = t.T_target_source;
  log_.info("computed " + pairText(t.pair()) + " in " + fixed(t.seconds, 2) + " s (" +
            std::to_string(computed.slice_pairs) + " slice pairs, " + std::to_string(computed.slice_pairs_recalled) +
            " kept from its last match): " +
            (t.reliable ? "x " + fixed(T.x, 3) + " y " + fixed(T.y, 3) + " z " + fixed(T.z, 3) + " yaw " +
                              fixed(T.yaw, 4) + ", by " + t.answered_by + ", " + fixed(t.lead_sigma, 1) + " sigma clear"
                        : "no reliable match: " + t.reason));
  bus_->publish(transport::toWire(t));
  const PairKey pair = t.pair();
  board_.computed(std::move(t));
  logIfKept(pair);
  agreedChanged();
}

}  // namespace tomomap::daemon
