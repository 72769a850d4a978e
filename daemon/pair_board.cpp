#include "pair_board.hpp"

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

PairBoard::PairBoard(std::string me, BoardTimings timings) : me_(std::move(me)), timings_(timings) {}

std::vector<AgreedTransform> PairBoard::mapAnnounced(const std::string& agent, uint64_t version) {
  maps_[agent] = {version, agent == me_};
  std::vector<AgreedTransform> stored;
  for (auto it = pending_.begin(); it != pending_.end();) {
    const PairKey& key = it->first.first;
    const bool decidable = (key.first == agent || key.second == agent) && versionOf(key.first) && versionOf(key.second);
    if (!decidable) {
      ++it;
      continue;
    }
    AgreedTransform t = std::move(it->second);
    it = pending_.erase(it);
    if (estimateSeen(t) == Offer::Stored) stored.push_back(std::move(t));
  }
  return stored;
}

void PairBoard::mapHeld(const std::string& agent) {
  if (const auto it = maps_.find(agent); it != maps_.end()) it->second.held = true;
}

void PairBoard::ownMap(uint64_t version) {
  mapAnnounced(me_, version);
  for (auto it = own_claims_.begin(); it != own_claims_.end();)
    it = (it->first.first == me_ || it->first.second == me_) ? own_claims_.erase(it) : std::next(it);
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
  const PairKey key = t.pair();
  const auto vt = versionOf(key.first), vs = versionOf(key.second);
  if ((vt && *vt != t.target_version) || (vs && *vs != t.source_version)) return Offer::Outdated;
  if (!vt || !vs) {
    // The announcement may still be on its way (estimates and announcements
    // travel apart): decide when it is here.
    pending_[{key, t.computed_by}] = std::move(t);
    return Offer::Pending;
  }
  for (const auto* held : {&results_, &unreliable_})
    if (const auto it = held->find(key); it != held->end() && it->second.isFor(t.target_version, t.source_version) &&
                                         !outranks(t.computed_by, it->second.computed_by))
      return Offer::Duplicate;  // the same result again, or a duplicate computation: keep one, deterministically
  store(std::move(t));
  claims_.erase(key);
  own_claims_.erase(key);
  return Offer::Stored;
}

void PairBoard::agentGone(const std::string& agent) {
  for (auto it = claims_.begin(); it != claims_.end();)
    it = it->second.claimer == agent ? claims_.erase(it) : std::next(it);
}

void PairBoard::leftNetwork() {
  claims_.clear();
  own_claims_.clear();
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
  std::vector<std::string> holders;  // in id order: maps_ is sorted
  for (const auto& [id, m] : maps_)
    if (m.held) holders.push_back(id);
  for (size_t i = 0; i < holders.size(); ++i)
    for (size_t j = i + 1; j < holders.size(); ++j) {
      const PairKey key{holders[i], holders[j]};
      const PairAt at = *heldPair(key);
      if (settled(key)) continue;
      const auto other = claims_.find(key);
      const bool live_other = other != claims_.end() && live(other->second, at, now);
      auto mine = own_claims_.find(key);
      if (mine != own_claims_.end() &&
          (mine->second.target_version != at.target_version || mine->second.source_version != at.source_version)) {
        own_claims_.erase(mine);  // claimed for maps that have changed since
        mine = own_claims_.end();
      }
      if (mine == own_claims_.end()) {
        if (live_other) continue;  // someone else is on it
        own_claims_[key] = {at.target_version, at.source_version, now};
        out.claims.push_back(at);
        continue;
      }
      if (now - mine->second.at < timings_.claim_settle) continue;
      if (live_other && outranks(other->second.claimer, me_)) {
        out.yielded.push_back(pairText(key) + " to " + other->second.claimer);
        own_claims_.erase(mine);
        continue;
      }
      computing_ = at;
      claim_renewed_ = now;
      out.compute = at;
      return out;
    }
  return out;
}

void PairBoard::computed(AgreedTransform t) {
  const PairKey key = t.pair();
  if (computing_ && computing_->pair == key) computing_.reset();
  own_claims_.erase(key);
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
    if (const auto mine = own_claims_.find(key); mine != own_claims_.end()) return {PairState::Claimed, me_, {}};
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
