// Pair-matching cost against the number of slices, both searches: a map pair
// cropped by height to a quarter, a half and all of its height (constant
// features per slice), matched indexed and --exhaustive. Prints the medians
// and log-log slopes and draws them (docs/img/scaling.png).
// Usage: bench_scaling TARGET.pcd SOURCE.pcd GRID OUT.png [RUNS]
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "core/matcher.hpp"
#include "core/stats.hpp"
#include "io/map_io.hpp"
#include "viz/line_plot.hpp"

using namespace tomomap;

namespace {

/// The points of `map` below `fraction` of its height.
Points lowest(const Points& map, double fraction) {
  float lo = map.front().z(), hi = lo;
  for (const auto& p : map) lo = std::min(lo, p.z()), hi = std::max(hi, p.z());
  const float cut = lo + static_cast<float>(fraction) * (hi - lo);
  Points out;
  for (const auto& p : map)
    if (p.z() <= cut) out.push_back(p);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: %s TARGET.pcd SOURCE.pcd GRID OUT.png [RUNS]\n", argv[0]);
    return 2;
  }
  MatchParams indexed;
  indexed.grid = std::stod(argv[3]);
  MatchParams exhaustive = indexed;
  exhaustive.exhaustive = true;
  const int runs = argc > 5 ? std::stoi(argv[5]) : 3;
  const Points target = loadMap(argv[1]), source = loadMap(argv[2]);

  viz::LineSeries fast{"indexed", {}, {}}, slow{"every pair (--exhaustive)", {}, {}};
  bool same = true;
  for (double fraction : {0.25, 0.5, 1.0}) {
    const MapFeatures t = describeMap(lowest(target, fraction), indexed);
    const MapFeatures s = describeMap(lowest(source, fraction), indexed);
    std::vector<double> a, b;
    MatchResult ra, rb;
    for (int i = 0; i < runs; ++i) {
      ra = matchFeatures(t, s, indexed);
      rb = matchFeatures(t, s, exhaustive);
      a.push_back(ra.timings.pair_matching);
      b.push_back(rb.timings.pair_matching);
    }
    same = same && ra.reliable == rb.reliable && ra.height_offset == rb.height_offset &&
           ra.features.support == rb.features.support;
    const double slices = (t.slice_count + s.slice_count) / 2.0;
    fast.x.push_back(slices), fast.y.push_back(quantile(a, 0.5));
    slow.x.push_back(slices), slow.y.push_back(quantile(b, 0.5));
    std::printf("%5.0f slices, %4.0f features a slice: indexed %.3f s (%zu of %zu pairs), every pair %.3f s\n", slices,
                static_cast<double>(t.featureCount() + s.featureCount()) /
                    static_cast<double>(t.slices.size() + s.slices.size()),
                quantile(a, 0.5), ra.features.slice_pairs, ra.features.slice_pairs_total, quantile(b, 0.5));
  }
  const double k_fast = viz::logLogSlope(fast.x, fast.y), k_slow = viz::logLogSlope(slow.x, slow.y);
  std::printf("log-log slope: indexed %.2f, every pair %.2f (medians of %d; %s answers)\n", k_fast, k_slow, runs,
              same ? "the same" : "DIFFERENT");
  char label[64];
  std::snprintf(label, sizeof label, " (slope %.2f)", k_fast);
  fast.name += label;
  std::snprintf(label, sizeof label, " (slope %.2f)", k_slow);
  slow.name += label;
  viz::writePng(argv[4],
                viz::drawLinePanel(
                    {"slice-pair matching against map height", "slices per map", "pair matching [s]", {fast, slow}},
                    viz::Axes::LogLog));
  return same ? 0 : 1;
}
