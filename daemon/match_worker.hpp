#pragma once
// Matching one pair on a thread of its own, so that the agent's loop keeps
// serving peers meanwhile. Each pair's slice-pair outcomes are remembered
// until it is matched again (a map update), which then re-estimates only the
// slice pairs whose content changed.
#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <thread>

#include "core/matcher.hpp"
#include "core/pair_cache.hpp"
#include "pair_board.hpp"

namespace tomomap::daemon {

class MatchWorker {
 public:
  /// `wake` is called from the worker thread when a result is ready.
  explicit MatchWorker(std::function<void()> wake) : wake_(std::move(wake)) {}
  ~MatchWorker();

  /// Starts matching `pair`; only when no match runs (the PairBoard starts one at a time).
  void start(const PairAt& pair, std::shared_ptr<const MapFeatures> target, std::shared_ptr<const MapFeatures> source,
             const MatchParams& params, const std::string& me);
  bool ready() const { return done_; }
  struct Computed {
    AgreedTransform transform;
    size_t slice_pairs = 0;           ///< slice pairs the search needed
    size_t slice_pairs_recalled = 0;  ///< of those, the ones remembered from the pair's last match
  };
  /// The result, once ready(); the worker is idle again afterwards.
  Computed take();
  /// Leaves a match in progress behind at exit: the fleet recomputes it.
  void abandon();

 private:
  std::function<void()> wake_;
  std::thread thread_;
  std::atomic<bool> done_{false};
  Computed result_;
  /// Touched only by the matching thread (one match at a time): at most one
  /// table's outcomes for each pair this agent computes.
  std::map<PairKey, PairCache> caches_;
};

/// The stored form of a match of `pair` computed by `me` on these maps (each levelled or not).
AgreedTransform agreedFromMatch(const PairAt& pair, const MatchResult& r, const MapFeatures& target,
                                const MapFeatures& source, const std::string& me);

}  // namespace tomomap::daemon
