#pragma once
// Matching one pair on a thread of its own, so that the agent's loop keeps
// serving peers meanwhile.
#include <atomic>
#include <functional>
#include <memory>
#include <thread>

#include "core/matcher.hpp"
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
  /// The result, once ready(); the worker is idle again afterwards.
  AgreedTransform take();
  /// Leaves a match in progress behind at exit: the fleet recomputes it.
  void abandon();

 private:
  std::function<void()> wake_;
  std::thread thread_;
  std::atomic<bool> done_{false};
  AgreedTransform result_;
};

/// The stored form of a match of `pair` computed by `me`.
AgreedTransform agreedFromMatch(const PairAt& pair, const MatchResult& r, const std::string& me);

}  // namespace tomomap::daemon
