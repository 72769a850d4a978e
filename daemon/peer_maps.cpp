#include "peer_maps.hpp"

#include <algorithm>
#include <climits>
#include <utility>

#include "core/text.hpp"
#include "results/agreed_transform.hpp"

namespace tomomap::daemon {
namespace {

constexpr size_t kTransfersKept = 8;
constexpr int kMaxBackoffDoublings = 4;  ///< requests back off to 16 x request_interval_s at most
/// How long samples of an unannounced version are held: an announcement can
/// lag its stream by the time discovery takes on a thin link (five agents at
/// 250 kbit/s: 20 s; with 10 s the samples held were dropped, and sent again
/// once asked for), but not by a participant lease (60 s): samples older than
/// that are a resend of an old version meant for another peer.
constexpr auto kEarlyHold = std::chrono::seconds(60);
/// How long a live peer's announcement may take before it is asked for:
/// durability brings it 0.4-3 s after the participant appears (seven agents
/// at 800 kbit/s), and asking too soon makes the owner announce to every
/// receiver (some 2 kB each).
constexpr auto kAnnouncementWait = std::chrono::seconds(5);

}  // namespace

wire::ChunkRequest PeerMaps::requestFor(const std::string& id, const PeerState& owner, bool everything,
                                        Clock::time_point now) const {
  const Peer& p = owner.map;
  wire::ChunkRequest r;
  r.requester(me_);
  r.owner(id);
  r.version(p.incoming->announcement().version());
  const auto quiet = std::chrono::duration_cast<std::chrono::milliseconds>(now - p.last_progress).count();
  r.stalled_ms(static_cast<uint32_t>(std::clamp<int64_t>(quiet, 0, UINT32_MAX)));
  r.received_through(owner.received_through);
  if (everything) return r;  // an empty list asks for every announced slice
  // Listed only once some slice is in: until then the empty list says the
  // same in 4 bytes a slice less (and the request reaches every receiver).
  auto missing = p.incoming->missing();
  if (missing.size() < p.incoming->sliceCount()) r.slices(std::move(missing));
  return r;
}

PeerMaps::Announced PeerMaps::announce(wire::MapAnnouncement a, Clock::time_point now) {
  const std::string owner = a.agent().to_string();
  PeerState& state = peers_[owner];
  state.unannounced.reset();
  Peer& p = state.map;
  if (p.incoming && p.incoming->announcement().version() == a.version()) return {};  // already known
  std::optional<transport::Reassembler> earlier = std::move(p.incoming);
  p = Peer{};
  p.incoming.emplace(std::move(a), memory_budget_);
  // A new version of a map we hold (or held in part): keep the unchanged slices.
  if (earlier) p.reused = p.incoming->adopt(*earlier);
  const auto& announced = p.incoming->announcement();
  log_.info("peer " + owner + " announced map version " + versionText(announced.version()) + ": " +
            std::to_string(announced.slices().size()) + " slices" +
            (earlier ? ", " + std::to_string(p.reused) + " of them unchanged from version " +
                           versionText(earlier->announcement().version())
                     : ""));
  p.last_progress = p.requested = p.last_request = now;
  const size_t early = takeEarly(owner, state, now);
  Announced out{true, false, std::nullopt};
  if (p.incoming->complete()) {
    complete(owner, state);
    out.complete = true;
  } else {
    out.request = requestFor(owner, state, /*everything=*/p.reused == 0 && early == 0, now);
  }
  return out;
}

void PeerMaps::noteTaken(PeerState& owner, uint64_t sequence) {
  owner.received_through = std::max(owner.received_through, sequence);
}

bool PeerMaps::tally(Peer& p, size_t bytes, Clock::time_point now) {
  const bool first = p.samples++ == 0;
  if (first) p.first_slice = now;
  p.bytes += bytes;
  p.last_slice = p.last_progress = now;
  p.unanswered = 0;
  return first;
}

void PeerMaps::holdEarly(PeerState& owner, const wire::SliceFeatures& s, size_t bytes, uint64_t sequence,
                         Clock::time_point now) const {
  Early& e = owner.early;
  if (e.version != s.version() || now - e.since > kEarlyHold) e = Early{s.version(), now, {}, 0};  // one version, fresh
  if (e.bytes + bytes > memory_budget_) return;  // the owner's budget holds for these too
  e.samples.push_back({s, bytes, sequence});
  e.bytes += bytes;
}

size_t PeerMaps::takeEarly(const std::string& id, PeerState& owner, Clock::time_point now) {
  Peer& p = owner.map;
  if (owner.early.samples.empty() || owner.early.version != p.incoming->announcement().version()) return 0;
  const Early held = std::exchange(owner.early, Early{});
  size_t taken = 0;
  for (const auto& [s, bytes, sequence] : held.samples) {
    noteTaken(owner, sequence);
    if (p.incoming->accept(s)) continue;  // checked as any sample is: a bad one is simply not taken
    tally(p, bytes, now);
    ++taken;
  }
  if (taken) log_.debug(id + ": " + std::to_string(taken) + " samples had arrived before the announcement");
  return taken;
}

PeerMaps::Received PeerMaps::receive(const wire::SliceFeatures& s, size_t bytes, uint64_t sequence,
                                     Clock::time_point now) {
  const std::string id = s.agent().to_string();
  PeerState& owner = peers_[id];
  Peer& p = owner.map;
  if (!p.incoming || p.incoming->announcement().version() != s.version()) {
    holdEarly(owner, s, bytes, sequence, now);  // its announcement may still be on the way
    return {};
  }
  noteTaken(owner, sequence);
  if (p.features) return {};  // complete already: a resend meant for another peer
  Received out;
  if ((out.rejection = p.incoming->accept(s))) return out;
  out.first = tally(p, bytes, now);
  if (p.incoming->complete()) {
    complete(id, owner);
    out.completed = true;
  }
  return out;
}

void PeerMaps::complete(const std::string& id, PeerState& owner) {
  Peer& p = owner.map;
  p.features = std::make_shared<MapFeatures>(p.incoming->build());
  const double span = p.samples ? seconds(p.last_slice - p.requested) : 0;
  auto& history = owner.transfers;
  history.push_back({p.incoming->announcement().version(), p.incoming->sliceCount(), p.reused, p.bytes, span});
  if (history.size() > kTransfersKept) history.pop_front();
  log_.info("received the map of " + id + ": " + std::to_string(p.incoming->sliceCount()) + " slices (" +
            std::to_string(p.reused) + " kept from the previous version), " + std::to_string(p.bytes) + " bytes in " +
            std::to_string(p.samples) + " samples, " + fixed(span, 2) + " s after our request (" +
            fixed(rateKbps(p), 0) + " kbit/s while sending)");
}

bool PeerMaps::waiting(const Peer& p) { return p.incoming && !p.features && !p.incoming->refused(); }

wire::ChunkRequest PeerMaps::askAgain(const std::string& id, PeerState& owner, Clock::time_point now) {
  Peer& p = owner.map;
  wire::ChunkRequest r = requestFor(id, owner, /*everything=*/false, now);
  p.last_request = now;
  ++p.unanswered;
  const size_t wanted = r.slices().empty() ? p.incoming->sliceCount() : r.slices().size();
  log_.info("asked " + id + " again for " + std::to_string(wanted) + " missing slices");
  return r;
}

std::vector<wire::ChunkRequest> PeerMaps::due(Clock::duration interval, Clock::time_point now) {
  std::vector<wire::ChunkRequest> out;
  for (auto& [id, owner] : peers_) {
    const Peer& p = owner.map;
    if (waiting(p)) {
      const auto quiet_since = std::max(p.last_progress, p.last_request);
      if (now - quiet_since >= interval * (1 << std::min(p.unanswered, kMaxBackoffDoublings)))
        out.push_back(askAgain(id, owner, now));
      continue;
    }
    if (!owner.alive || p.incoming) continue;
    if (!owner.unannounced) {
      owner.unannounced = Unannounced{now, 0};
      continue;
    }
    Unannounced& u = *owner.unannounced;
    if (now - u.since < kAnnouncementWait * (1 << std::min(u.asked, kMaxBackoffDoublings))) continue;
    u.since = now;
    ++u.asked;
    wire::ChunkRequest r;
    r.requester(me_);
    r.owner(id);
    r.version(kNoVersion);
    out.push_back(r);
    log_.info("asked " + id + " for its announcement: none has come since its participant appeared");
  }
  return out;
}

std::optional<wire::ChunkRequest> PeerMaps::askNow(const std::string& owner, Clock::time_point now) {
  const auto it = peers_.find(owner);
  if (it == peers_.end() || !waiting(it->second.map)) return std::nullopt;
  return askAgain(owner, it->second, now);
}

std::shared_ptr<const MapFeatures> PeerMaps::features(const std::string& peer) const {
  const auto it = peers_.find(peer);
  return it == peers_.end() ? nullptr : it->second.map.features;
}

std::optional<uint64_t> PeerMaps::version(const std::string& peer) const {
  const auto it = peers_.find(peer);
  if (it == peers_.end() || !it->second.map.incoming) return std::nullopt;
  return it->second.map.incoming->announcement().version();
}

bool PeerMaps::setAlive(const std::string& peer, bool alive) {
  PeerState& state = peers_[peer];
  state.received_through = 0;
  state.unannounced.reset();
  return std::exchange(state.alive, alive) != alive;
}

void PeerMaps::clearAlive() {
  for (auto& [id, state] : peers_) {
    state.alive = false;
    state.received_through = 0;
    state.unannounced.reset();
  }
}

size_t PeerMaps::aliveCount() const {
  return static_cast<size_t>(
      std::count_if(peers_.begin(), peers_.end(), [](const auto& entry) { return entry.second.alive; }));
}

std::set<std::string> PeerMaps::alive() const {
  std::set<std::string> ids;
  for (const auto& [id, state] : peers_)
    if (state.alive) ids.insert(id);
  return ids;
}

PeerMaps::Totals PeerMaps::totals() const {
  Totals t;
  for (const auto& [id, state] : peers_) {
    const Peer& p = state.map;
    if (!p.incoming) continue;
    t.maps += p.features != nullptr;
    t.slices_done += p.incoming->slicesDone();
    t.slices_all += p.incoming->sliceCount();
  }
  return t;
}

double PeerMaps::rateKbps(const Peer& p) {
  if (p.samples < 2) return 0;
  const double span = seconds(p.last_slice - p.first_slice) + transport::kFlowPeriodMs / 1000.0;
  return static_cast<double>(p.bytes) * 8 / 1000 / span;
}

nlohmann::json PeerMaps::status(const transport::PeerAddress& peer) const {
  const auto it = peers_.find(peer.id);
  const PeerState none;
  const PeerState& state = it == peers_.end() ? none : it->second;
  nlohmann::json j{{"alive", state.alive}, {"host", peer.host}, {"port", peer.port}};
  if (state.last_seen_ms) j["last_seen_ms"] = *state.last_seen_ms;
  if (const Peer& p = state.map; p.incoming) {
    j["version"] = versionText(p.incoming->announcement().version());
    j["slices_received"] = p.incoming->slicesDone();
    j["slices_total"] = p.incoming->sliceCount();
    j["slices_reused"] = p.reused;
    j["bytes_received"] = p.bytes;
    j["samples_received"] = p.samples;
    j["complete"] = p.features != nullptr;
    j["transfer_seconds"] = p.samples ? seconds(p.last_slice - p.requested) : 0.0;
    j["rate_kbps"] = rateKbps(p);
  }
  nlohmann::json history = nlohmann::json::array();
  for (const auto& x : state.transfers)
    history.push_back({{"version", versionText(x.version)},
                       {"slices", x.slices},
                       {"slices_reused", x.reused},
                       {"bytes", x.bytes},
                       {"seconds", x.seconds}});
  j["transfers"] = history;
  return j;
}

}  // namespace tomomap::daemon
