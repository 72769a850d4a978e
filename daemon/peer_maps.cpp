#include "peer_maps.hpp"

#include <algorithm>
#include <climits>

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

wire::ChunkRequest PeerMaps::requestFor(const std::string& owner, const Peer& p, bool everything,
                                        Clock::time_point now) const {
  wire::ChunkRequest r;
  r.requester(me_);
  r.owner(owner);
  r.version(p.incoming->announcement().version());
  const auto quiet = std::chrono::duration_cast<std::chrono::milliseconds>(now - p.last_progress).count();
  r.stalled_ms(static_cast<uint32_t>(std::clamp<int64_t>(quiet, 0, UINT32_MAX)));
  const auto through = received_through_.find(owner);
  r.received_through(through == received_through_.end() ? 0 : through->second);
  if (everything) return r;  // an empty list asks for every announced slice
  // Listed only once some slice is in: until then the empty list says the
  // same in 4 bytes a slice less (and the request reaches every receiver).
  auto missing = p.incoming->missing();
  if (missing.size() < p.incoming->sliceCount()) r.slices(std::move(missing));
  return r;
}

PeerMaps::Announced PeerMaps::announce(wire::MapAnnouncement a, Clock::time_point now) {
  const std::string owner = a.agent().to_string();
  unannounced_.erase(owner);
  Peer& p = peers_[owner];
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
  const size_t early = takeEarly(owner, p, now);
  Announced out{true, false, std::nullopt};
  if (p.incoming->complete()) {
    complete(owner, p);
    out.complete = true;
  } else {
    out.request = requestFor(owner, p, /*everything=*/p.reused == 0 && early == 0, now);
  }
  return out;
}

void PeerMaps::noteTaken(const std::string& owner, uint64_t sequence) {
  uint64_t& through = received_through_[owner];
  through = std::max(through, sequence);
}

bool PeerMaps::tally(Peer& p, size_t bytes, Clock::time_point now) {
  const bool first = p.samples++ == 0;
  if (first) p.first_slice = now;
  p.bytes += bytes;
  p.last_slice = p.last_progress = now;
  p.unanswered = 0;
  return first;
}

void PeerMaps::holdEarly(const std::string& owner, const wire::SliceFeatures& s, size_t bytes, uint64_t sequence,
                         Clock::time_point now) {
  Early& e = early_[owner];
  if (e.version != s.version() || now - e.since > kEarlyHold) e = Early{s.version(), now, {}, 0};  // one version, fresh
  if (e.bytes + bytes > memory_budget_) return;  // the owner's budget holds for these too
  e.samples.push_back({s, bytes, sequence});
  e.bytes += bytes;
}

size_t PeerMaps::takeEarly(const std::string& owner, Peer& p, Clock::time_point now) {
  const auto it = early_.find(owner);
  if (it == early_.end() || it->second.version != p.incoming->announcement().version()) return 0;
  size_t taken = 0;
  for (const auto& [s, bytes, sequence] : it->second.samples) {
    noteTaken(owner, sequence);
    if (p.incoming->accept(s)) continue;  // checked as any sample is: a bad one is simply not taken
    tally(p, bytes, now);
    ++taken;
  }
  early_.erase(it);
  if (taken) log_.debug(owner + ": " + std::to_string(taken) + " samples had arrived before the announcement");
  return taken;
}

PeerMaps::Received PeerMaps::receive(const wire::SliceFeatures& s, size_t bytes, uint64_t sequence,
                                     Clock::time_point now) {
  const std::string owner = s.agent().to_string();
  const auto it = peers_.find(owner);
  if (it == peers_.end() || !it->second.incoming || it->second.incoming->announcement().version() != s.version()) {
    holdEarly(owner, s, bytes, sequence, now);  // its announcement may still be on the way
    return {};
  }
  noteTaken(owner, sequence);
  Peer& p = it->second;
  if (p.features) return {};  // complete already: a resend meant for another peer
  Received out;
  if ((out.rejection = p.incoming->accept(s))) return out;
  out.first = tally(p, bytes, now);
  if (p.incoming->complete()) {
    complete(it->first, p);
    out.completed = true;
  }
  return out;
}

void PeerMaps::complete(const std::string& owner, Peer& p) {
  p.features = std::make_shared<MapFeatures>(p.incoming->build());
  const double span = p.samples ? seconds(p.last_slice - p.requested) : 0;
  auto& history = transfers_[owner];
  history.push_back({p.incoming->announcement().version(), p.incoming->sliceCount(), p.reused, p.bytes, span});
  if (history.size() > kTransfersKept) history.pop_front();
  log_.info("received the map of " + owner + ": " + std::to_string(p.incoming->sliceCount()) + " slices (" +
            std::to_string(p.reused) + " kept from the previous version), " + std::to_string(p.bytes) + " bytes in " +
            std::to_string(p.samples) + " samples, " + fixed(span, 2) + " s after our request (" +
            fixed(rateKbps(p), 0) + " kbit/s while sending)");
}

bool PeerMaps::waiting(const Peer& p) { return p.incoming && !p.features && !p.incoming->refused(); }

wire::ChunkRequest PeerMaps::askAgain(const std::string& owner, Peer& p, Clock::time_point now) {
  wire::ChunkRequest r = requestFor(owner, p, /*everything=*/false, now);
  p.last_request = now;
  ++p.unanswered;
  const size_t wanted = r.slices().empty() ? p.incoming->sliceCount() : r.slices().size();
  log_.info("asked " + owner + " again for " + std::to_string(wanted) + " missing slices");
  return r;
}

std::vector<wire::ChunkRequest> PeerMaps::due(Clock::duration interval, Clock::time_point now) {
  std::vector<wire::ChunkRequest> out;
  for (auto& [id, p] : peers_) {
    if (!waiting(p)) continue;
    const auto quiet_since = std::max(p.last_progress, p.last_request);
    if (now - quiet_since < interval * (1 << std::min(p.unanswered, kMaxBackoffDoublings))) continue;
    out.push_back(askAgain(id, p, now));
  }
  for (const auto& id : alive_) {
    const auto held = peers_.find(id);
    if (held != peers_.end() && held->second.incoming) continue;
    const auto [it, first] = unannounced_.try_emplace(id, Unannounced{now, 0});
    Unannounced& u = it->second;
    if (first || now - u.since < kAnnouncementWait * (1 << std::min(u.asked, kMaxBackoffDoublings))) continue;
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
  if (it == peers_.end() || !waiting(it->second)) return std::nullopt;
  return askAgain(owner, it->second, now);
}

std::shared_ptr<const MapFeatures> PeerMaps::features(const std::string& peer) const {
  const auto it = peers_.find(peer);
  return it == peers_.end() ? nullptr : it->second.features;
}

std::optional<uint64_t> PeerMaps::version(const std::string& peer) const {
  const auto it = peers_.find(peer);
  if (it == peers_.end() || !it->second.incoming) return std::nullopt;
  return it->second.incoming->announcement().version();
}

bool PeerMaps::setAlive(const std::string& peer, bool alive) {
  received_through_.erase(peer);
  unannounced_.erase(peer);
  return alive ? alive_.insert(peer).second : alive_.erase(peer) > 0;
}

PeerMaps::Totals PeerMaps::totals() const {
  Totals t;
  for (const auto& [id, p] : peers_) {
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
  nlohmann::json j{{"alive", alive_.count(peer.id) > 0}, {"host", peer.host}, {"port", peer.port}};
  if (const auto seen = last_seen_ms_.find(peer.id); seen != last_seen_ms_.end()) j["last_seen_ms"] = seen->second;
  const auto it = peers_.find(peer.id);
  if (it != peers_.end() && it->second.incoming) {
    const Peer& p = it->second;
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
  if (const auto t = transfers_.find(peer.id); t != transfers_.end())
    for (const auto& x : t->second)
      history.push_back({{"version", versionText(x.version)},
                         {"slices", x.slices},
                         {"slices_reused", x.reused},
                         {"bytes", x.bytes},
                         {"seconds", x.seconds}});
  j["transfers"] = history;
  return j;
}

}  // namespace tomomap::daemon
