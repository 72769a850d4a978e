#include "pair_board.hpp"

#include <algorithm>
#include <functional>
#include <set>

namespace tomomap::daemon {

const char* stateName(PairState s) {
  switch (s) {
    case PairState::WaitingForMaps:
      return "waiting for maps";
    case PairState::Open:
      return "open";
    case PairState::ClaimedByPeer:
      return "claimed";
    case PairState::Claimed:
      return "claimed by us";
    case PairState::Computing:
      return "computing";
    case PairState::Agreed:
      return "agreed";
    case PairState::Stale:
      return "stale";
    case PairState::Kept:
      return "kept";
  }
  return "?";
}

std::vector<std::string> computeOrder(const PairKey& pair, const std::vector<std::string>& fleet) {
  const size_t n = fleet.size();
  const auto at = [&](const std::string& id) {
    return static_cast<size_t>(std::lower_bound(fleet.begin(), fleet.end(), id) - fleet.begin());
  };
  const size_t i = at(pair.first), j = at(pair.second);
  if (n == 0 || i >= n || j >= n || fleet[i] != pair.first || fleet[j] != pair.second) return {};
  std::vector<std::string> order;
  for (size_t k = 0; k < n; ++k) order.push_back(fleet[(i + j + 1 + k) % n]);
  return order;
}

PairBoard::PairBoard(std::string me, BoardTimings timings) : me_(std::move(me)), timings_(timings) { setFleet({}); }

void PairBoard::setFleet(std::vector<std::string> agents) {
  agents.push_back(me_);
  std::sort(agents.begin(), agents.end());
  agents.erase(std::unique(agents.begin(), agents.end()), agents.end());
  fleet_ = std::move(agents);
  presumeUp();
}

void PairBoard::presumeUp() {
  // Until its participant is reported gone, a peer may be on a pair already:
  // one not discovered yet (discovery takes seconds on a busy machine) had
  // claimed pairs this agent then computed as well.
  up_.clear();
  for (const auto& id : fleet_)
    if (id != me_) up_.insert(id);
}

std::vector<AgreedTransform> PairBoard::mapAnnounced(const std::string& agent, uint64_t version) {
  maps_[agent] = {version, agent == me_};
  std::vector<AgreedTransform> stored;
  for (auto it = pending_.begin(); it != pending_.end();) {
    const AgreedTransform& t = it->second;
    const PairKey& key = it->first.first;
    if (key.first != agent && key.second != agent) {
      ++it;
      continue;
    }
    const uint64_t its_version = key.first == agent ? t.target_version : t.source_version;
    if (its_version != version) {
      it = pending_.erase(it);  // the map is at another version now: the estimate is not for it
      continue;
    }
    if (!isCurrent(t)) {
      ++it;  // the other map's announcement may still be on its way
      continue;
    }
    AgreedTransform current = std::move(it->second);
    it = pending_.erase(it);
    if (estimateSeen(current) == Offer::Stored) stored.push_back(std::move(current));
  }
  return stored;
}

void PairBoard::mapHeld(const std::string& agent) {
  if (const auto it = maps_.find(agent); it != maps_.end()) it->second.held = true;
}

void PairBoard::ownMap(uint64_t version) {
  mapAnnounced(me_, version);
  if (own_claim_ && (own_claim_->first.pair.first == me_ || own_claim_->first.pair.second == me_)) own_claim_.reset();
}

std::optional<uint64_t> PairBoard::versionOf(const std::string& agent) const {
  const auto it = maps_.find(agent);
  if (it == maps_.end()) return std::nullopt;
  return it->second.version;
}

std::optional<PairAt> PairBoard::heldPair(const PairKey& key) const {
  const auto t = maps_.find(key.first), s = maps_.find(key.second);
  if (t == maps_.end() || s == maps_.end() || !t->second.held || !s->second.held) return std::nullopt;
  return PairAt{key, t->second.version, s->second.version};
}

bool PairBoard::live(const Claim& c, const PairAt& at, Clock::time_point now) const {
  return c.target_version == at.target_version && c.source_version == at.source_version &&
         now - c.seen < timings_.claim_timeout;
}

void PairBoard::claimSeen(const std::string& claimer, const PairAt& claim, Clock::time_point now) {
  Claim& held = claims_[claim.pair];
  // Keep the claim that wins: the highest-ranked claimer among live ones.
  const bool replace =
      held.claimer.empty() || !outranks(held.claimer, claimer) || now - held.seen > timings_.claim_timeout;
  if (replace) held = {claimer, claim.target_version, claim.source_version, now};
}

PairBoard::Offer PairBoard::estimateSeen(AgreedTransform t) {
  if (!isCurrent(t)) {
    // Estimates and announcements travel apart: this one may be ahead of the
    // announcement of a map's new version (the soak run saw a peer compute a
    // pair for its new map before that map's announcement reached us), or
    // replayed from before. Versions are hashes, so the two look alike: the
    // next announcement of either map decides (mapAnnounced).
    pending_[{t.pair(), t.computed_by}] = std::move(t);
    return Offer::Pending;
  }
  const PairKey key = t.pair();
  for (const auto* held : {&results_, &unreliable_})
    if (const auto it = held->find(key); it != held->end() && it->second.isFor(t.target_version, t.source_version) &&
                                         !outranks(t.computed_by, it->second.computed_by))
      return Offer::Duplicate;  // the same result again, or a duplicate computation: keep one, deterministically
  store(std::move(t));
  claims_.erase(key);
  if (own_claim_ && own_claim_->first.pair == key) own_claim_.reset();
  return Offer::Stored;
}

void PairBoard::agentGone(const std::string& agent) {
  up_.erase(agent);
  for (auto it = claims_.begin(); it != claims_.end();)
    it = it->second.claimer == agent ? claims_.erase(it) : std::next(it);
}

void PairBoard::leftNetwork() {
  claims_.clear();
  own_claim_.reset();
  presumeUp();
}

BoardStep PairBoard::step(Clock::time_point now) {
  BoardStep out;
  if (computing_) {
    if (now - claim_renewed_ >= timings_.claim_timeout / 4) {
      out.claims.push_back(*computing_);
      claim_renewed_ = now;
    }
    return out;
  }
  if (own_claim_) {
    settleOwnClaim(now, out);
    if (own_claim_ || out.compute) return out;  // still settling, or computing now
  }
  if (const std::optional<PairAt> next = nextClaim(now)) {
    own_claim_ = {*next, now};
    out.claims.push_back(*next);
  }
  return out;
}

void PairBoard::settleOwnClaim(Clock::time_point now, BoardStep& out) {
  const PairKey key = own_claim_->first.pair;
  const std::optional<PairAt> at = heldPair(key);
  if (!at || settled(key) || at->target_version != own_claim_->first.target_version ||
      at->source_version != own_claim_->first.source_version) {
    own_claim_.reset();  // claimed for maps that have changed since, or answered meanwhile
    return;
  }
  if (now - own_claim_->second < timings_.claim_settle) return;
  if (const auto other = claims_.find(key);
      other != claims_.end() && live(other->second, *at, now) && outranks(other->second.claimer, me_)) {
    out.yielded.push_back(pairText(key) + " to " + other->second.claimer);
    own_claim_.reset();
    return;
  }
  own_claim_.reset();
  computing_ = at;
  claim_renewed_ = now;
  out.compute = at;
}

size_t PairBoard::turn(const PairKey& key) const {
  size_t ahead = 0;
  for (const auto& id : computeOrder(key, fleet_)) {
    if (id == me_) return ahead;
    ahead += up_.count(id);
  }
  return ahead;  // a pair outside our fleet (a peer list that differs): no turn to wait for
}

std::optional<PairAt> PairBoard::nextClaim(Clock::time_point now) {
  // The agents the agreed transforms connect already, as components.
  std::map<std::string, std::string> parent;
  const std::function<std::string(const std::string&)> root = [&](const std::string& a) {
    const auto it = parent.find(a);
    return it == parent.end() || it->second == a ? a : it->second = root(it->second);
  };
  for (const auto& [key, t] : results_)
    if (t.reliable && isCurrent(t)) parent[root(key.first)] = root(key.second);

  std::optional<PairAt> joining, closing;  // the first in key order of each kind
  for (auto a = maps_.begin(); a != maps_.end(); ++a)
    for (auto b = std::next(a); b != maps_.end(); ++b) {
      const PairKey key{a->first, b->first};
      const std::optional<PairAt> at = heldPair(key);
      const auto other = claims_.find(key);
      if (!at || settled(key) || (other != claims_.end() && live(other->second, *at, now))) {
        unclaimed_since_.erase(key);
        continue;
      }
      const auto since = unclaimed_since_.emplace(key, now).first->second;
      if (now - since < timings_.claim_timeout * static_cast<int>(turn(key))) continue;  // not our turn yet
      auto& first = root(key.first) == root(key.second) ? closing : joining;
      if (!first) first = *at;  // every pair is still visited: its unclaimed time is kept above
    }
  return joining ? joining : closing;
}

void PairBoard::computed(AgreedTransform t) {
  const PairKey key = t.pair();
  if (computing_ && computing_->pair == key) computing_.reset();
  store(std::move(t));
}

void PairBoard::store(AgreedTransform t) {
  const PairKey key = t.pair();
  const auto it = results_.find(key);
  if (!t.reliable && it != results_.end() && it->second.reliable &&
      !it->second.isFor(t.target_version, t.source_version)) {
    unreliable_[key] = std::move(t);
    return;
  }
  unreliable_.erase(key);
  results_[key] = std::move(t);
}

bool PairBoard::settled(const PairKey& key) const {
  for (const auto* held : {&results_, &unreliable_})
    if (const auto it = held->find(key); it != held->end() && isCurrent(it->second)) return true;
  return false;
}

bool PairBoard::isCurrent(const AgreedTransform& t) const {
  const auto vt = versionOf(t.target), vs = versionOf(t.source);
  return vt && vs && t.isFor(*vt, *vs);
}

size_t PairBoard::currentResults() const {
  size_t n = 0;
  for (const auto& [key, t] : results_) n += isCurrent(t);
  return n;
}

PairStatus PairBoard::status(const PairKey& key, Clock::time_point now) const {
  const auto done = results_.find(key);
  if (computing_ && computing_->pair == key) return {PairState::Computing, me_, {}};
  if (done != results_.end() && isCurrent(done->second)) return {PairState::Agreed, done->second.computed_by, {}};
  if (const auto kept = unreliable_.find(key); kept != unreliable_.end() && isCurrent(kept->second))
    return {PairState::Kept, kept->second.computed_by, kept->second.reason};
  const std::optional<PairAt> at = heldPair(key);
  if (at) {
    if (own_claim_ && own_claim_->first.pair == key) return {PairState::Claimed, me_, {}};
    if (const auto other = claims_.find(key); other != claims_.end() && live(other->second, *at, now))
      return {PairState::ClaimedByPeer, other->second.claimer, {}};
  }
  if (done != results_.end()) return {PairState::Stale, done->second.computed_by, {}};
  return {at ? PairState::Open : PairState::WaitingForMaps, {}, {}};
}

std::vector<PairKey> PairBoard::pairs() const {
  std::set<PairKey> all;
  for (auto a = maps_.begin(); a != maps_.end(); ++a)
    for (auto b = std::next(a); b != maps_.end(); ++b) all.insert({a->first, b->first});
  for (const auto& [key, t] : results_) all.insert(key);
  return {all.begin(), all.end()};
}

}  // namespace tomomap::daemon
