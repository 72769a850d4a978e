#pragma once
// Who computes which pair, and what the fleet agreed: one state per pair of
// agents, driven by the maps this agent holds, by claims and estimates from
// the network and by its own decisions. Pure: no DDS, no threads, no clock of
// its own (the time is passed in), so races can be replayed in unit tests.
#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "clock.hpp"
#include "results/agreed_transform.hpp"

namespace tomomap::daemon {

/// The tie-break, written once: of two agents that claim, or computed, the
/// same pair at the same versions, the one with the lower id wins.
inline bool outranks(const std::string& a, const std::string& b) { return a < b; }

/// A pair at the versions of its two maps.
struct PairAt {
  PairKey pair;
  uint64_t target_version = 0, source_version = 0;
};

enum class PairState {
  WaitingForMaps,  ///< this agent does not hold both maps at their announced versions
  Open,            ///< both maps held, nobody on it yet
  ClaimedByPeer,   ///< another agent's live claim for these versions
  Claimed,         ///< our claim, waiting for competing claims to show up
  Computing,       ///< our worker is matching it
  Agreed,          ///< a result for the current versions
  Stale,           ///< a result for earlier versions, and nobody on the new ones yet
  /// The current versions gave no reliable match: the reliable result for
  /// earlier versions stays the agreed one (an unreliable answer never
  /// replaces a reliable one), and the pair is not computed again.
  Kept,
};
const char* stateName(PairState s);

struct PairStatus {
  PairState state = PairState::WaitingForMaps;
  std::string by;   ///< the claimer (ClaimedByPeer) or the computing agent (Agreed, Stale, Kept)
  std::string why;  ///< Kept: why the current versions gave no reliable match
};

struct BoardTimings {
  Clock::duration claim_timeout{};  ///< a claim without a result is void after this (config: claim_timeout_s)
  Clock::duration claim_settle = std::chrono::milliseconds(500);  ///< time for competing claims to show up
};

/// What this agent is to do now.
struct BoardStep {
  std::vector<PairAt> claims;        ///< publish a claim for each
  std::vector<std::string> yielded;  ///< "pair to claimer", for the log
  std::optional<PairAt> compute;     ///< start matching this pair
};

/// Who computes a pair when all is well, written once: the fleet's agents in
/// id order, from position (i + j + 1) mod n on, where i < j are the pair's
/// positions. Every agent derives the same order from the same fleet, so each
/// pair has one computer without a message, and the n(n-1)/2 pairs spread
/// evenly: each agent is first for (n-1)/2 of them, give or take one half.
std::vector<std::string> computeOrder(const PairKey& pair, const std::vector<std::string>& fleet);

class PairBoard {
 public:
  PairBoard(std::string me, BoardTimings timings);
  void setTimings(BoardTimings t) { timings_ = t; }
  /// The agents of the fleet as this agent's config lists them (itself and its peers).
  void setFleet(std::vector<std::string> agents);

  // ---- what this agent knows of each map
  /// `agent` announced `version` (not yet held, unless it is ours).
  /// Returns the estimates held back (estimateSeen) that are now stored.
  std::vector<AgreedTransform> mapAnnounced(const std::string& agent, uint64_t version);
  /// This agent now holds `agent`'s map at its announced version.
  void mapHeld(const std::string& agent);
  /// Our own map has a new version: our claims made with the old one are void.
  void ownMap(uint64_t version);
  /// Forgets the maps of every peer `keep` rejects (removed from the config).
  template <typename Keep>
  void retainMaps(Keep keep) {
    for (auto it = maps_.begin(); it != maps_.end();)
      it = it->first == me_ || keep(it->first) ? std::next(it) : maps_.erase(it);
  }
  std::optional<uint64_t> versionOf(const std::string& agent) const;

  // ---- from the network
  void claimSeen(const std::string& claimer, const PairAt& claim, Clock::time_point now);
  /// Whether an estimate from the network was stored. Only an estimate for
  /// the maps' announced versions is. Any other is held back (Pending, one per
  /// pair and computer): it may be ahead of an announcement on its way. It is
  /// stored once both its versions are announced, and dropped once either map
  /// is announced at another version, so a replayed old estimate never
  /// replaces a result. Of two estimates for the same versions every agent
  /// keeps the one of the higher-ranked computer.
  enum class Offer { Stored, Duplicate, Pending };
  Offer estimateSeen(AgreedTransform t);
  /// A peer's participant is up (again): it can compute the pairs that are its turn.
  void agentUp(const std::string& agent) { up_.insert(agent); }
  /// A peer's participant is gone: its claims are void and its turns pass on
  /// at once. Peers are presumed up until then (setFleet).
  void agentGone(const std::string& agent);
  /// This agent left the network (and joins again): every claim is void.
  void leftNetwork();

  // ---- this agent's decisions
  /// Claims one pair it is about to compute: whose maps are held, that nobody
  /// is on, and that is its turn (computeOrder: first among the agents not
  /// reported gone; the
  /// k-th once the pair has gone unclaimed here for k claim timeouts, so a
  /// stuck or busy agent's pairs pass on). Of its pairs, those joining agents
  /// the agreed transforms do not connect yet come first. Starts computing it
  /// once the claim has settled and no higher-ranked claimer contests it.
  /// At most one computation at a time; while it runs, its claim is renewed
  /// every quarter of the claim timeout, so that a match slower than the
  /// timeout (a big map, a busy machine) is not taken over and done twice.
  BoardStep step(Clock::time_point now);
  /// A result this agent stored before it restarted (transforms.json): held
  /// like any other, current while the maps' announced versions match it.
  void restore(AgreedTransform t) { store(std::move(t)); }
  /// Our worker's result for the pair being computed: stored (even if the
  /// versions moved on meanwhile: then the pair is stale and is recomputed).
  void computed(AgreedTransform t);
  const std::optional<PairAt>& computing() const { return computing_; }

  // ---- what the fleet agreed
  const std::map<PairKey, AgreedTransform>& results() const { return results_; }
  /// Unreliable answers for the current versions held beside an earlier reliable result (Kept).
  const std::map<PairKey, AgreedTransform>& keptBeside() const { return unreliable_; }
  /// Whether `t` was computed for the maps' versions known now.
  bool isCurrent(const AgreedTransform& t) const;
  size_t currentResults() const;
  PairStatus status(const PairKey& pair, Clock::time_point now) const;
  /// Every pair among the agents whose maps we know (and those with results).
  std::vector<PairKey> pairs() const;

 private:
  struct MapState {
    uint64_t version = 0;
    bool held = false;
  };
  struct Claim {
    std::string claimer;
    uint64_t target_version = 0, source_version = 0;
    Clock::time_point seen;
  };
  bool live(const Claim& c, const PairAt& at, Clock::time_point now) const;
  /// How many claim timeouts this agent waits before it claims an unclaimed
  /// pair: its place among the agents up in the pair's computeOrder.
  size_t turn(const PairKey& key) const;
  /// Every peer of the fleet counts as up (at start, and after rejoining).
  void presumeUp();
  /// The pair this agent claims next, if any is its turn: the first in key
  /// order that joins agents the agreed transforms do not connect yet, else
  /// the first that closes a loop.
  std::optional<PairAt> nextClaim(Clock::time_point now);
  /// Our claim waiting to settle: computes, yields or drops it.
  void settleOwnClaim(Clock::time_point now, BoardStep& out);
  /// Stores a result, unless it is unreliable and would replace a reliable one for earlier versions.
  void store(AgreedTransform t);
  /// Whether the current versions of a pair have an answer (reliable or not).
  bool settled(const PairKey& key) const;
  std::optional<PairAt> heldPair(const PairKey& key) const;

  std::string me_;
  BoardTimings timings_;
  std::map<std::string, MapState> maps_;
  std::map<PairKey, Claim> claims_;                                ///< the winning claim of other agents per pair
  std::optional<std::pair<PairAt, Clock::time_point>> own_claim_;  ///< the pair we claimed, and when
  std::vector<std::string> fleet_;                                 ///< this agent and its configured peers, in id order
  std::set<std::string> up_;                                       ///< peers whose participant is up
  /// Since when each held, unsettled pair has gone without a live claim here.
  std::map<PairKey, Clock::time_point> unclaimed_since_;
  /// Estimates for versions other than the announced ones, per pair and computer.
  std::map<std::pair<PairKey, std::string>, AgreedTransform> pending_;
  std::optional<PairAt> computing_;
  Clock::time_point claim_renewed_{};  ///< when the computing pair's claim was last published
  std::map<PairKey, AgreedTransform> results_;
  std::map<PairKey, AgreedTransform> unreliable_;
};

}  // namespace tomomap::daemon
