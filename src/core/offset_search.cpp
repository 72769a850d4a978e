#include "offset_search.hpp"

#include <algorithm>

#include "height_offsets.hpp"
#include "offset_votes.hpp"

namespace tomomap {
namespace {

/// Offsets matched either side of a vote peak and of the winner and runner-up:
/// refinement uses the winner's neighbours, and a neighbour with more support
/// must be seen to be climbed to.
constexpr int kSearchMargin = 1;

/// Vote peaks followed: the strongest few, down to half of the strongest. A
/// second floor that fits as well as the first (the two-floor test) has as
/// many votes; the true offset's neighbours, fewer than the true offset but
/// no peaks of their own.
constexpr double kPeakShare = 0.5;
constexpr size_t kMaxPeaks = 4;

/// Slice pairs sampled on every height offset: a safety net for maps whose
/// descriptors do not tell heights apart (a street of uniform facades votes
/// for every offset alike), where the true offset shows only in the slice
/// pairs' geometric agreement.
constexpr size_t kSamplesPerOffset = 8;

/// An offset is matched in full once its sampled support, scaled to its whole
/// diagonal, reaches this share of the best full support so far: a sample of
/// 8 pairs misjudges an offset's support by up to about half (synth street
/// and building, demo-room): at half the best, every rival with support
/// near the winner's is matched in full and proposed (rival_answers.hpp).
constexpr double kRivalShare = 0.5;

/// A winner under this many times min_support is checked against every pair:
/// a rival to it (below) needs at most min_support agreeing pairs, too few for
/// a sample of eight to tell from none.
constexpr int kEveryPairBelow = 2;

/// A winner with fewer than this many times min_support slice pairs is weak:
/// its rivals are followed by an absolute margin (another answer within
/// min_support pairs of it) rather than by a share of its support. On small
/// rooms a wrong transform, repeated over a few similar slices, won 3-5 to
/// 2-4 against another wrong one; rooms came out wrong at 7 slice pairs
/// against 3 and at 15 against 5.
constexpr int kStrongWinner = 5;

/// The slice pairs on each height offset's diagonal (target slice index -
/// source slice index), as table indices by increasing target slice.
class Diagonals {
 public:
  Diagonals(const MapFeatures& target, const MapFeatures& source, const SlicePairTable& table)
      : first_(target.slices.front().index - source.slices.back().index),
        pairs_(static_cast<size_t>(target.slices.back().index - source.slices.front().index - first_ + 1)) {
    for (size_t a = 0; a < table.nt; ++a)
      for (size_t b = 0; b < table.ns; ++b)
        at(target.slices[a].index - source.slices[b].index).push_back(table.index(a, b));
  }
  int first() const { return first_; }
  int last() const { return first_ + static_cast<int>(pairs_.size()) - 1; }
  const std::vector<size_t>& of(int offset) const {
    static const std::vector<size_t> none;
    return offset < first_ || offset > last() ? none : pairs_[static_cast<size_t>(offset - first_)];
  }

 private:
  std::vector<size_t>& at(int offset) { return pairs_[static_cast<size_t>(offset - first_)]; }
  int first_;
  std::vector<std::vector<size_t>> pairs_;
};

/// Adds the pairs of `offset` and kSearchMargin offsets either side.
void addAround(int offset, const Diagonals& d, std::vector<size_t>& out) {
  for (int o = offset - kSearchMargin; o <= offset + kSearchMargin; ++o)
    out.insert(out.end(), d.of(o).begin(), d.of(o).end());
}

/// Adds at most `count` of `pairs`, spread evenly along them.
void addSpread(const std::vector<size_t>& pairs, size_t count, std::vector<size_t>& out) {
  const size_t take = std::min(count, pairs.size());
  for (size_t i = 0; i < take; ++i) out.push_back(pairs[(2 * i + 1) * pairs.size() / (2 * take)]);
}

/// Adds at most `count` pairs of every offset, spread evenly along its diagonal.
void addSamples(const Diagonals& d, size_t count, std::vector<size_t>& out) {
  for (int o = d.first(); o <= d.last(); ++o) addSpread(d.of(o), count, out);
}

/// The pairs to match next, given what the matched ones say: none once the
/// winner and the runner-up stand among matched neighbours and no sampled
/// offset promises a rival.
std::vector<size_t> nextPairs(const SlicePairTable& table, const Diagonals& diagonals, const MapFeatures& target,
                              const MapFeatures& source, const MatchParams& params) {
  std::vector<size_t> todo;
  const std::vector<OffsetScore> scores = scoreOffsets(table, target, source, params);
  const OffsetChoice choice = pickOffset(scores, params, source.centre());
  const int best = choice.best ? static_cast<int>(choice.best->consensus.support()) : 0;
  if (!choice.best || best < kEveryPairBelow * params.min_support) {
    for (size_t k = 0; k < table.matched.size(); ++k)
      if (!table.matched[k]) todo.push_back(k);
    return todo;
  }
  // The support a rival is judged against: the winner's, or for a weak winner
  // the least that brings another answer within min_support pairs of it
  // (kStrongWinner), an absolute margin the winner's share misses.
  const int judged = best < kStrongWinner * params.min_support ? best - params.min_support + 1 : best;
  addAround(choice.best->offset, diagonals, todo);
  if (choice.runner_up_support > 0) addAround(choice.runner_up_offset, diagonals, todo);
  for (const OffsetScore& s : scores) {
    const std::vector<size_t>& pairs = diagonals.of(s.offset);
    const auto matched =
        static_cast<size_t>(std::count_if(pairs.begin(), pairs.end(), [&](size_t k) { return table.matched[k] != 0; }));
    const double projected = static_cast<double>(s.consensus.support() * pairs.size()) / static_cast<double>(matched);
    if (matched < pairs.size() && projected >= kRivalShare * judged) {
      // Twice the sample, not the whole diagonal at once: on a street of
      // uniform facades one agreeing pair in eight projects a rival on half
      // the offsets, and most of them fall back once sixteen are matched.
      std::vector<size_t> unmatched;
      for (size_t k : pairs)
        if (!table.matched[k]) unmatched.push_back(k);
      addSpread(unmatched, matched, todo);
    }
  }
  todo.erase(std::remove_if(todo.begin(), todo.end(), [&](size_t k) { return table.matched[k] != 0; }), todo.end());
  return todo;
}

}  // namespace

SlicePairTable matchSlicePairs(const MapFeatures& target, const MapFeatures& source, const MatchParams& params,
                               const Progress& progress, const PairCache* cache) {
  if (params.exhaustive || target.slices.empty() || source.slices.empty())
    return estimateSlicePairs(target, source, params, progress, cache);
  SlicePairTable table(target, source);
  const Diagonals diagonals(target, source, table);
  std::vector<size_t> todo;
  for (int peak : voteHeightOffsets(target, source, matchThreads(params)).peaks(kSmearSlices, kPeakShare, kMaxPeaks))
    addAround(peak, diagonals, todo);
  addSamples(diagonals, kSamplesPerOffset, todo);
  while (!todo.empty()) {
    estimateSlicePairs(table, todo, target, source, params, progress, cache);
    todo = nextPairs(table, diagonals, target, source, params);
  }
  return table;
}

}  // namespace tomomap
