#include "match_worker.hpp"

#include "clock.hpp"

namespace tomomap::daemon {

MatchWorker::~MatchWorker() {
  if (thread_.joinable()) thread_.join();
}

AgreedTransform agreedFromMatch(const PairAt& pair, const MatchResult& r, const MapFeatures& target,
                                const MapFeatures& source, const std::string& me) {
  AgreedTransform t = agreedOf(r, target, source);
  t.target = pair.pair.first;
  t.source = pair.pair.second;
  t.target_version = pair.target_version;
  t.source_version = pair.source_version;
  t.computed_by = me;
  return t;
}

void MatchWorker::start(const PairAt& pair, std::shared_ptr<const MapFeatures> target,
                        std::shared_ptr<const MapFeatures> source, const MatchParams& params, const std::string& me) {
  done_ = false;
  thread_ = std::thread([this, pair, target = std::move(target), source = std::move(source), params, me] {
    const auto t0 = Clock::now();
    Computed c;
    AgreedTransform& t = c.transform;
    try {
      const MatchResult r = matchFeatures(*target, *source, params, {}, &caches_[pair.pair]);
      t = agreedFromMatch(pair, r, *target, *source, me);
      c.slice_pairs = r.features.slice_pairs;
      c.slice_pairs_recalled = r.features.slice_pairs_recalled;
    } catch (const std::exception& ex) {
      t = agreedFromMatch(pair, MatchResult{}, *target, *source, me);
      t.reason = ex.what();
    }
    t.computed_at_ms = wallMs();
    t.seconds = seconds(Clock::now() - t0);
    result_ = std::move(c);
    done_ = true;
    wake_();
  });
}

MatchWorker::Computed MatchWorker::take() {
  thread_.join();
  done_ = false;
  return std::move(result_);
}

void MatchWorker::abandon() {
  if (thread_.joinable() && !done_) thread_.detach();
}

}  // namespace tomomap::daemon
