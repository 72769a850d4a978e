#include "offset_votes.hpp"

#include <omp.h>

#include <algorithm>
#include <array>

#include "hamming.hpp"

namespace tomomap {
namespace {

/// Look-alikes: within this Hamming distance of 256 bits. Mutual matches that
/// support the winning offset have a median distance of 22-36 (demo-room,
/// synth building at g 0.05-0.1).
constexpr int kLookAlikeRadius = 32;
/// Tables of the index, each keyed by one 16-bit chunk of the descriptor.
/// Eight give a clear peak at the true offset; sixteen cost twice as much and
/// gave the same peaks (synth building at g 0.05).
constexpr int kTables = 8;
constexpr uint32_t kBuckets = 1u << 16;
/// A bucket holding more descriptors than this is a chunk too common to tell
/// anything (and the whole cost at fine grids: 0.8 s uncapped, 0.05 s capped,
/// on the synth building at g 0.05 with 120 k descriptors a map).
constexpr uint32_t kMaxBucket = 100;
/// One source descriptor's vote, split among its look-alikes in whole units
/// so that the sum does not depend on the order threads add it in.
constexpr uint64_t kVote = 1u << 16;

/// Every descriptor of a map as four 64-bit words, with its slice index.
struct FlatDescriptors {
  std::vector<uint64_t> words;
  std::vector<int> slice;
  size_t size() const { return slice.size(); }
  const uint64_t* at(size_t i) const { return &words[i * 4]; }
};

FlatDescriptors flatten(const MapFeatures& map) {
  FlatDescriptors f;
  f.words.reserve(map.featureCount() * 4);
  f.slice.reserve(map.featureCount());
  for (const SliceFeatures& s : map.slices) {
    const std::vector<uint64_t> w = descriptorWords(s.descriptors);
    f.words.insert(f.words.end(), w.begin(), w.end());
    f.slice.insert(f.slice.end(), static_cast<size_t>(s.descriptors.rows), s.index);
  }
  return f;
}

uint32_t chunk(const uint64_t* words, int table) {
  return static_cast<uint32_t>((words[table / 4] >> (16 * (table % 4))) & 0xFFFFu);
}

/// Per table, the descriptors in each bucket (counting sort: starts, then members).
struct ChunkIndex {
  std::array<std::vector<uint32_t>, kTables> start, member;

  explicit ChunkIndex(const FlatDescriptors& d) {
    for (int t = 0; t < kTables; ++t) {
      std::vector<uint32_t>& s = start[static_cast<size_t>(t)];
      s.assign(kBuckets + 1, 0);
      for (size_t i = 0; i < d.size(); ++i) ++s[chunk(d.at(i), t) + 1];
      for (uint32_t b = 0; b < kBuckets; ++b) s[b + 1] += s[b];
      std::vector<uint32_t> next(s.begin(), s.end() - 1);
      std::vector<uint32_t>& m = member[static_cast<size_t>(t)];
      m.resize(d.size());
      for (size_t i = 0; i < d.size(); ++i) m[next[chunk(d.at(i), t)]++] = static_cast<uint32_t>(i);
    }
  }
};

}  // namespace

std::vector<int> OffsetVotes::peaks(int radius, double share, size_t count) const {
  const uint64_t most = votes.empty() ? 0 : *std::max_element(votes.begin(), votes.end());
  std::vector<int> out;
  if (most == 0) return out;
  for (int o = first_offset; o <= lastOffset(); ++o) {
    const uint64_t v = at(o);
    if (static_cast<double>(v) < share * static_cast<double>(most)) continue;
    bool highest = true;  // ties go to the lower offset
    for (int d = -radius; d <= radius && highest; ++d)
      if (d != 0) highest = d < 0 ? at(o + d) < v : at(o + d) <= v;
    if (highest) out.push_back(o);
  }
  std::stable_sort(out.begin(), out.end(), [&](int a, int b) { return at(a) > at(b); });
  if (out.size() > count) out.resize(count);
  return out;
}

OffsetVotes voteHeightOffsets(const MapFeatures& target, const MapFeatures& source, int threads) {
  OffsetVotes v;
  if (target.slices.empty() || source.slices.empty()) return v;
  v.first_offset = target.slices.front().index - source.slices.back().index;
  v.votes.assign(static_cast<size_t>(target.slices.back().index - source.slices.front().index - v.first_offset + 1), 0);
  const FlatDescriptors t = flatten(target), s = flatten(source);
  const ChunkIndex index(t);
#pragma omp parallel num_threads(threads)
  {
    std::vector<uint64_t> mine(v.votes.size(), 0);
    std::vector<uint32_t> seen_by(t.size(), UINT32_MAX);  // the query that last looked at each target descriptor
    std::vector<int> alike;
#pragma omp for schedule(dynamic, 256)
    for (long long q = 0; q < static_cast<long long>(s.size()); ++q) {
      const uint64_t* x = s.at(static_cast<size_t>(q));
      alike.clear();
      for (int tb = 0; tb < kTables; ++tb) {
        const auto& start = index.start[static_cast<size_t>(tb)];
        const uint32_t key = chunk(x, tb), first = start[key], last = start[key + 1];
        if (last - first > kMaxBucket) continue;
        for (uint32_t k = first; k < last; ++k) {
          const uint32_t i = index.member[static_cast<size_t>(tb)][k];
          if (seen_by[i] == static_cast<uint32_t>(q)) continue;
          seen_by[i] = static_cast<uint32_t>(q);
          if (hamming256(x, t.at(i)) <= kLookAlikeRadius) alike.push_back(t.slice[i]);
        }
      }
      if (alike.empty()) continue;
      const uint64_t share = kVote / alike.size();
      for (int ti : alike) mine[static_cast<size_t>(ti - s.slice[static_cast<size_t>(q)] - v.first_offset)] += share;
    }
#pragma omp critical(tomomap_offset_votes)
    for (size_t i = 0; i < mine.size(); ++i) v.votes[i] += mine[i];
  }
  return v;
}

}  // namespace tomomap
