#include "agent.hpp"

#include <unistd.h>

#include <algorithm>

#include "core/map_io.hpp"
#include "core/matcher.hpp"
#include "agent_detail.hpp"
#include "state_files.hpp"

namespace tomomap::daemon {
using namespace detail;

namespace {

constexpr size_t kPcdHeaderBytes = 190;  ///< a binary PCD header for x y z float
constexpr auto kClaimSettle = std::chrono::milliseconds(500);  ///< time for competing claims to show up

}  // namespace

Agent::Agent(Config config, Log& log) : config_(std::move(config)), log_(log) {}

Agent::~Agent() {
  if (worker_.joinable()) worker_.join();
}

void Agent::post(std::function<void()> work) {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    queue_.push_back(std::move(work));
  }
  queue_cv_.notify_one();
}

OwnMap describeOwnMap(const Config& config) {
  const auto t0 = Clock::now();
  OwnMap own;
  auto features = [&] {
    const Points map = loadMap(config.map);  // dropped once described
    validateMap(map, config.map);
    MatchParams params;
    params.grid = config.grid;
    return std::make_shared<MapFeatures>(describeMap(map, params, nullptr, &own.cells));
  }();
  const uint64_t raw_bytes = 12 * own.cells + kPcdHeaderBytes;
  own.offer = transport::makeOffer(config.agent(), *features, raw_bytes,
                                   transport::maxSampleBytes(config.transport.bandwidth_kbps));
  own.features = std::move(features);
  own.seconds = seconds(Clock::now() - t0);
  return own;
}

void Agent::installOwnMap(OwnMap own) {
  const bool update = own_features_ != nullptr;
  const uint64_t before = offer_.announcement.version();
  offer_ = std::move(own.offer);
  own_features_ = std::move(own.features);
  map_updated_ms_ = wallMs();
  // Queued parts belong to the old version: peers ask again for what they need.
  send_queue_.clear();
  queued_.clear();
  next_part_ = 0;
  leaves_at_.clear();
  for (auto it = own_claims_.begin(); it != own_claims_.end();)  // claimed with the old version
    it = (it->first.first == config_.agent() || it->first.second == config_.agent()) ? own_claims_.erase(it)
                                                                                     : std::next(it);
  size_t as_cells = 0;
  for (const auto& [k, samples] : offer_.samples) as_cells += samples.front().encoding() == wire::SliceEncoding::OCCUPANCY;
  const auto& a = offer_.announcement;
  log_.info(std::string(update ? "map updated: " : "map ") + config_.map + ": " + std::to_string(own.cells) +
            " cells at g " + fixed(config_.grid, 3) + " m, " + std::to_string(a.slices().size()) +
            " descriptive slices (" + std::to_string(as_cells) + " sent as occupancy, the rest as features), " +
            std::to_string(own_features_->featureCount()) + " features; version " + versionText(a.version()) +
            (update ? " (was " + versionText(before) + ")" : "") + "; payload " + std::to_string(offer_.payload_bytes) +
            " bytes = " +
            fixed(100.0 * static_cast<double>(offer_.payload_bytes) / static_cast<double>(a.raw_bytes()), 1) +
            " % of the voxel-filtered map's binary PCD (" + std::to_string(a.raw_bytes()) + " bytes); described in " +
            fixed(own.seconds, 2) + " s");
  if (bus_) {
    bus_->publish(offer_.announcement);
    persist(false);
  }
}

bool Agent::fromKnown(const std::string& sender, const char* what) {
  if (!known(sender, what)) return false;
  last_seen_ms_[sender] = wallMs();  // callers have set aside our own samples
  return true;
}

bool Agent::known(const std::string& agent, const char* what) {
  if (agent == config_.agent() || config_.isPeer(agent)) return true;
  ++counters_.unknown_agent;
  log_.debug(std::string("dropped ") + what + " from unknown agent '" + agent + "'");
  return false;
}

void Agent::reject(const std::string& from, const std::string& why) {
  ++counters_.rejected;
  log_.warning("rejected a sample from " + from + ": " + why);
}

std::optional<uint64_t> Agent::versionOf(const std::string& agent) const {
  if (agent == config_.agent()) return offer_.announcement.version();
  const auto it = peers_.find(agent);
  if (it == peers_.end() || !it->second.incoming) return std::nullopt;
  return it->second.incoming->announcement().version();
}

bool Agent::isCurrent(const wire::TransformEstimate& e) const {
  const auto vt = versionOf(e.target().to_string()), vs = versionOf(e.source().to_string());
  return vt && vs && *vt == e.target_version() && *vs == e.source_version();
}

std::shared_ptr<const MapFeatures> Agent::featuresOf(const std::string& agent) const {
  if (agent == config_.agent()) return own_features_;
  const auto it = peers_.find(agent);
  return it == peers_.end() ? nullptr : it->second.features;
}

void Agent::onAnnouncement(wire::MapAnnouncement&& a) {
  if (a.agent().to_string() == config_.agent() || !fromKnown(a.agent().to_string(), "an announcement")) return;
  if (const auto why = transport::validate(a); !why.empty()) return reject(a.agent().to_string(), why);
  const std::string owner = a.agent().to_string();
  PeerMap& p = peers_[owner];
  if (p.incoming && p.incoming->announcement().version() == a.version()) return;  // already known
  std::optional<transport::Reassembler> earlier = std::move(p.incoming);
  p = PeerMap{};
  p.incoming.emplace(std::move(a));
  // A new version of a map we hold (or held in part): keep the unchanged slices.
  if (earlier) p.reused = p.incoming->adopt(*earlier);
  const auto& announced = p.incoming->announcement();
  log_.info("peer " + owner + " announced map version " + versionText(announced.version()) + ": " +
            std::to_string(announced.slices().size()) + " slices" +
            (earlier ? ", " + std::to_string(p.reused) + " of them unchanged from version " +
                           versionText(earlier->announcement().version())
                     : ""));
  p.last_progress = p.requested = p.last_request = Clock::now();
  if (p.incoming->complete()) return completeTransfer(owner, p);
  wire::ChunkRequest r;
  r.requester(config_.agent());
  r.owner(owner);
  r.version(announced.version());
  if (p.reused > 0) r.slices(p.incoming->missing());  // else an empty list: everything
  bus_->publish(r);
}

void Agent::onSlice(wire::SliceFeatures&& s, size_t bytes) {
  if (s.agent().to_string() == config_.agent() || !fromKnown(s.agent().to_string(), "a slice")) return;
  const auto it = peers_.find(s.agent().to_string());
  if (it == peers_.end() || !it->second.incoming || it->second.incoming->announcement().version() != s.version())
    return;  // a version we were not told about (yet) or no longer want
  PeerMap& p = it->second;
  if (p.features) return;  // complete already: a resend meant for another peer
  if (const auto why = p.incoming->accept(s); !why.empty()) return reject(s.agent().to_string(), why);
  const auto now = Clock::now();
  if (p.samples++ == 0) {
    p.first_slice = now;
    persist(false);  // status shows a transfer under way at once, not a second later
  }
  p.bytes += bytes;
  p.last_slice = p.last_progress = now;
  if (p.incoming->complete()) completeTransfer(s.agent().to_string(), p);
}

void Agent::completeTransfer(const std::string& owner, PeerMap& p) {
  p.features = std::make_shared<MapFeatures>(p.incoming->build({}));
  const double span = p.samples ? seconds(p.last_slice - p.requested) : 0;
  auto& history = transfers_[owner];
  history.push_back({p.incoming->announcement().version(), p.incoming->sliceCount(), p.reused, p.bytes, span});
  if (history.size() > 8) history.pop_front();
  log_.info("received the map of " + owner + ": " + std::to_string(p.incoming->sliceCount()) + " slices (" +
            std::to_string(p.reused) + " kept from the previous version), " + std::to_string(p.bytes) + " bytes in " +
            std::to_string(p.samples) + " samples, " + fixed(span, 2) + " s after our request (" +
            fixed(rateKbps(p), 0) + " kbit/s while sending)");
  persist(false);
}

void Agent::onRequest(wire::ChunkRequest&& r) {
  if (r.requester().to_string() == config_.agent() || r.owner().to_string() != config_.agent()) return;
  if (!fromKnown(r.requester().to_string(), "a request")) return;
  if (r.version() != offer_.announcement.version()) return;  // an old version: the announcement tells them
  std::vector<int> wanted;
  if (r.slices().empty())
    for (const auto& e : offer_.announcement.slices()) wanted.push_back(e.slice());
  else
    for (int32_t k : r.slices())
      if (offer_.samples.count(k)) wanted.push_back(k);
  const auto now = Clock::now();
  const auto grace = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(config_.request_interval_s));
  for (int k : wanted) {
    const auto leaving = leaves_at_.find(k);
    if (leaving != leaves_at_.end() && now < leaving->second + grace) continue;  // still on its way
    if (queued_.insert(k).second) send_queue_.push_back(k);
  }
  log_.debug(r.requester().to_string() + " asked for " + std::to_string(wanted.size()) + " slices; " +
             std::to_string(send_queue_.size()) + " queued");
}

void Agent::onClaim(wire::MatchClaim&& c) {
  if (c.claimer().to_string() == config_.agent() || !fromKnown(c.claimer().to_string(), "a claim")) return;
  const PairKey key{c.target().to_string(), c.source().to_string()};
  Claim& held = claims_[key];
  // Keep the claim that wins: lowest claimer id among current ones.
  const bool replace = held.claimer.empty() || c.claimer().to_string() <= held.claimer ||
                       seconds(Clock::now() - held.seen) > config_.claim_timeout_s;
  if (replace) held = {c.claimer().to_string(), c.target_version(), c.source_version(), Clock::now()};
  log_.debug(c.claimer().to_string() + " claims " + pairText(key));
}

void Agent::onEstimate(wire::TransformEstimate&& e) {
  if (e.computed_by().to_string() == config_.agent()) return;  // our own, stored already
  if (!known(e.target().to_string(), "an estimate") || !known(e.source().to_string(), "an estimate") ||
      !fromKnown(e.computed_by().to_string(), "an estimate"))
    return;
  if (e.target().to_string() >= e.source().to_string()) return reject(e.computed_by().to_string(), "estimate with an unordered pair");
  for (double v : {e.x(), e.y(), e.z(), e.yaw()})
    if (!std::isfinite(v)) return reject(e.computed_by().to_string(), "estimate with a non-finite transform");
  const PairKey key{e.target().to_string(), e.source().to_string()};
  const auto vt = versionOf(e.target().to_string()), vs = versionOf(e.source().to_string());
  const bool current = (!vt || *vt == e.target_version()) && (!vs || *vs == e.source_version());
  const auto it = results_.find(key);
  if (!current && it != results_.end()) return;  // we hold a result for newer maps
  if (it != results_.end() && it->second.target_version() == e.target_version() &&
      it->second.source_version() == e.source_version() && it->second.computed_by().to_string() <= e.computed_by().to_string())
    return;  // the same result again (or a duplicate computation: keep one, deterministically)
  log_.info("agreed " + pairText(key) + " from " + e.computed_by().to_string() + ": x " + fixed(e.x(), 3) + " y " +
            fixed(e.y(), 3) + " z " + fixed(e.z(), 3) + " yaw " + fixed(e.yaw(), 4) +
            (e.reliable() ? "" : " (no reliable match: " + e.reason().to_string() + ")"));
  results_[key] = std::move(e);
  claims_.erase(key);
  own_claims_.erase(key);
  persist(true);
}

void Agent::onPeer(const std::string& name, bool alive) {
  const std::string prefix = "tomomapd/";
  if (name.rfind(prefix, 0) != 0) return;
  const std::string id = name.substr(prefix.size());
  if (!config_.isPeer(id)) {
    log_.debug("participant '" + name + "' is not in the config; its samples will be dropped");
    return;
  }
  if (alive) {
    if (alive_.insert(id).second) log_.info("peer " + id + " is up");
    requestMissing(/*at_once=*/true);  // a request sent before it could hear us was lost
    // A late joiner gets what this agent computed, in case durability missed it.
    for (const auto& [key, e] : results_)
      if (e.computed_by().to_string() == config_.agent()) bus_->publish(e);
  } else if (alive_.erase(id)) {
    log_.warning("peer " + id + " is gone");
    for (auto it = claims_.begin(); it != claims_.end();)
      it = it->second.claimer == id ? claims_.erase(it) : std::next(it);
  }
}

void Agent::pumpSends() {
  while (!send_queue_.empty()) {
    const int k = send_queue_.front();
    const auto& samples = offer_.samples.at(k);
    if (!bus_->publish(samples[next_part_])) return;  // the writer's queue is full: next tick
    const size_t bytes = transport::Bus::serializedSize(samples[next_part_]);
    counters_.bytes_sent += bytes;
    ++counters_.samples_sent;
    const auto now = Clock::now();
    backlog_until_ = std::max(backlog_until_, now) +
                     std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                         static_cast<double>(bytes) * 8 / 1000 / config_.transport.bandwidth_kbps));
    leaves_at_[k] = backlog_until_;
    if (++next_part_ == samples.size()) {
      next_part_ = 0;
      send_queue_.pop_front();
      queued_.erase(k);
    }
  }
}

double Agent::rateKbps(const PeerMap& p) const {
  if (p.samples < 2) return 0;
  const double span = seconds(p.last_slice - p.first_slice) + transport::kFlowPeriodMs / 1000.0;
  return static_cast<double>(p.bytes) * 8 / 1000 / span;
}

void Agent::requestMissing(bool at_once) {
  const auto now = Clock::now();
  for (auto& [id, p] : peers_) {
    if (!p.incoming || p.features) continue;
    const auto quiet_since = std::max(p.last_progress, p.last_request);
    if (!at_once && seconds(now - quiet_since) < config_.request_interval_s) continue;
    wire::ChunkRequest r;
    r.requester(config_.agent());
    r.owner(id);
    r.version(p.incoming->announcement().version());
    r.slices(p.incoming->missing());
    bus_->publish(r);
    p.last_request = now;
    log_.info("asked " + id + " again for " + std::to_string(r.slices().size()) + " missing slices");
  }
}

void Agent::claimAndCompute() {
  if (computing_) return;
  std::vector<std::string> holders{config_.agent()};
  for (const auto& [id, p] : peers_)
    if (p.features) holders.push_back(id);
  std::sort(holders.begin(), holders.end());
  const auto now = Clock::now();
  for (size_t i = 0; i < holders.size(); ++i)
    for (size_t j = i + 1; j < holders.size(); ++j) {
      const PairKey key{holders[i], holders[j]};
      const uint64_t vt = *versionOf(key.first), vs = *versionOf(key.second);
      const auto done = results_.find(key);
      if (done != results_.end() && isCurrent(done->second)) continue;
      const auto other = claims_.find(key);
      const bool live_other = other != claims_.end() && other->second.target_version == vt &&
                              other->second.source_version == vs &&
                              seconds(now - other->second.seen) < config_.claim_timeout_s;
      const auto mine = own_claims_.find(key);
      if (mine == own_claims_.end()) {
        if (live_other) continue;  // someone else is on it
        wire::MatchClaim c;
        c.target(key.first);
        c.source(key.second);
        c.target_version(vt);
        c.source_version(vs);
        c.claimer(config_.agent());
        c.claimed_at_ms(wallMs());
        bus_->publish(c);
        own_claims_[key] = now;
        log_.info("claimed " + pairText(key));
        continue;
      }
      if (now - mine->second < kClaimSettle) continue;
      if (live_other && other->second.claimer < config_.agent()) {  // the tie-break: lowest id computes
        log_.info("yielding " + pairText(key) + " to " + other->second.claimer);
        own_claims_.erase(mine);
        continue;
      }
      // Compute on a worker so the loop keeps serving peers meanwhile.
      computing_ = key;
      worker_done_ = false;
      auto target = featuresOf(key.first), source = featuresOf(key.second);
      const double grid = config_.grid;
      const std::string me = config_.agent();
      worker_ = std::thread([this, key, target, source, grid, me, vt, vs] {
        const auto t0 = Clock::now();
        MatchParams params;
        params.grid = grid;
        wire::TransformEstimate e;
        e.target(key.first);
        e.source(key.second);
        e.target_version(vt);
        e.source_version(vs);
        e.computed_by(me);
        try {
          const MatchResult r = matchFeatures(*target, *source, params);
          e.reliable(r.reliable);
          e.reason(r.reason.substr(0, 120));
          const Pose4& T = r.T_target_source;
          e.x(T.x);
          e.y(T.y);
          e.z(T.z);
          e.yaw(T.yaw);
          const Eigen::Matrix4d M = T.matrix();
          for (int row = 0; row < 4; ++row)
            for (int col = 0; col < 4; ++col) e.matrix()[static_cast<size_t>(4 * row + col)] = M(row, col);
          e.support(r.support);
          e.runner_up_support(r.runner_up_support);
          e.inliers(static_cast<uint32_t>(r.inliers));
          e.spread({r.inlier_spread.x(), r.inlier_spread.y(), r.inlier_spread.z()});
        } catch (const std::exception& ex) {
          e.reliable(false);
          e.reason(std::string(ex.what()).substr(0, 120));
        }
        e.computed_at_ms(wallMs());
        e.seconds(seconds(Clock::now() - t0));
        computed_ = std::move(e);
        worker_done_ = true;
        queue_cv_.notify_one();
      });
      log_.info("computing " + pairText(key));
      return;
    }
}

void Agent::finishCompute() {
  if (!computing_ || !worker_done_) return;
  worker_.join();
  const PairKey key = *computing_;
  computing_.reset();
  own_claims_.erase(key);
  ++counters_.matches_computed;
  const auto& e = computed_;
  log_.info("computed " + pairText(key) + " in " + fixed(e.seconds(), 2) + " s: " +
            (e.reliable() ? "x " + fixed(e.x(), 3) + " y " + fixed(e.y(), 3) + " z " + fixed(e.z(), 3) + " yaw " +
                                fixed(e.yaw(), 4) + ", support " + std::to_string(e.support()) + ", " +
                                std::to_string(e.inliers()) + " inliers"
                          : "no reliable match: " + e.reason().to_string()));
  // Versions may have moved on while matching: then the next round recomputes.
  results_[key] = computed_;
  bus_->publish(computed_);
  persist(true);
}

}  // namespace tomomap::daemon
