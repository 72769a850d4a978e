// A map update, timed: the source map gains a cabinet (a few slices change);
// it is described again from scratch and on its previous version (what the
// daemon does: ORB only where it changed), and the pair is matched again from
// scratch and with the slice pairs of the first match recalled (core/pair_cache.hpp).
// Usage: bench_rematch TARGET.pcd SOURCE.pcd GRID [RUNS]
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "core/matcher.hpp"
#include "core/pair_cache.hpp"
#include "core/stats.hpp"
#include "io/map_io.hpp"
#include "support.hpp"

using namespace tomomap;
using test::secondsOf;

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s TARGET.pcd SOURCE.pcd GRID [RUNS]\n", argv[0]);
    return 2;
  }
  MatchParams p;
  p.grid = std::stod(argv[3]);
  const int runs = argc > 4 ? std::stoi(argv[4]) : 5;
  const Points source = loadMap(argv[2]);
  const MapFeatures target = describeMap(loadMap(argv[1]), p);
  const Points updated = test::withCabinet(source);
  const MapFeatures before = describeMap(source, p), after = describeMap(updated, p);

  std::vector<double> whole, changed;
  MapFeatures redescribed;
  for (int i = 0; i < runs; ++i) {
    whole.push_back(secondsOf([&] { describeMap(updated, p); }));
    changed.push_back(secondsOf([&] { redescribed = describeMap(updated, p, nullptr, nullptr, &before); }));
  }
  const int occupied = redescribed.occupancy.occupiedSlices();
  std::printf(
      "describe after a cabinet, g %.2f, median of %d: from scratch %.3f s, on the previous version %.3f s (ORB on "
      "%d of %d slices)\n",
      p.grid, runs, quantile(whole, 0.5), quantile(changed, 0.5), occupied - redescribed.kept_slices, occupied);

  std::vector<double> fresh, recalled;
  MatchResult a, b;
  for (int i = 0; i < runs; ++i) {
    fresh.push_back(secondsOf([&] { a = matchFeatures(target, after, p); }));
    PairCache cache;
    matchFeatures(target, before, p, {}, &cache);
    recalled.push_back(secondsOf([&] { b = matchFeatures(target, after, p, {}, &cache); }));
  }
  const bool same = a.reliable == b.reliable && a.T_target_source.x == b.T_target_source.x &&
                    a.T_target_source.yaw == b.T_target_source.yaw && a.features.support == b.features.support;
  std::printf(
      "re-match after a cabinet, g %.2f, median of %d: from scratch %.3f s, recalling %.3f s (%zu of %zu "
      "slice pairs recalled, %s answer)\n",
      p.grid, runs, quantile(fresh, 0.5), quantile(recalled, 0.5), b.features.slice_pairs_recalled,
      b.features.slice_pairs, same ? "the same" : "A DIFFERENT");
  return same ? 0 : 1;
}
