// The verdict as a truth table: evidence in, which search answers (or why
// none does, or what it still needs) out. Each row is a rule of
// docs/algorithm.md, "No reliable match", with the figures that decide it.
#include <gtest/gtest.h>

#include "core/verdict.hpp"

using namespace tomomap;
using By = Verdict::By;
using Needs = Verdict::Needs;

namespace {

/// A feature answer: `support` slice pairs against `runner_up`, 100 inliers.
FeatureEvidence featureAnswer(int support, int runner_up = 0) {
  FeatureEvidence f;
  f.support = support;
  f.runner_up_support = runner_up;
  f.runner_up_gap = 12;
  f.inliers = 100;
  return f;
}

/// A landed pose of `telling` cells, `contradicted` in the other map's empty space, on `slices` slices.
DensePose landed(size_t telling, size_t contradicted = 0, int slices = 10) {
  DensePose p;
  p.telling_inliers = telling;
  p.contradicted = contradicted;
  p.inliers = telling;
  p.support = slices;
  p.support_seen = slices;
  return p;
}

/// A dense search whose best pose has `best`'s counts, its next scoring `next`.
DenseEvidence search(const DensePose& best, double next, bool at_features = false, double cell = 0.1) {
  DenseEvidence d;
  d.found = true;
  d.best = best;
  d.next_score = next;
  d.at_features = at_features;
  d.cell = cell;
  d.apart = 2.5;
  return d;
}

struct Row {
  const char* rule;
  Evidence evidence;
  By by;
  Needs needs;
  const char* reason;  ///< the reason begins so (by none, needs nothing)
};

/// A second look at a dense pose that finds it again, its origin `apart` [m] away.
SecondLook lookedAgain(double apart = 0) {
  SecondLook l;
  l.found = true;
  l.same_place = true;
  l.apart = apart;
  return l;
}

/// The evidence of a row; a thin feature answer's wide search (asked first)
/// found nothing unless the row says otherwise, and a second look at a dense
/// pose finds it again.
Evidence with(FeatureEvidence f, std::optional<DenseEvidence> grid = std::nullopt, double cell = 0.1) {
  Evidence e;
  e.features = std::move(f);
  e.grid = cell;
  e.at_grid = std::move(grid);
  e.wide = DenseEvidence{};
  e.second_look = lookedAgain();
  return e;
}

/// A thin feature answer (1 slice pair) and its wide search.
Evidence thinWith(const DenseEvidence& wide) {
  Evidence e = with(featureAnswer(1));
  e.wide = wide;
  return e;
}

}  // namespace

TEST(Verdict, TruthTable) {
  MatchParams params;  // min_support 3, min_inliers 20: weak winners lead by under 15
  FeatureEvidence none_found;
  none_found.missing = "no slice pair produced an estimate";
  FeatureEvidence few_inliers = featureAnswer(30);
  few_inliers.inliers = 10;

  std::vector<Row> rows;
  auto add = [&](const char* rule, Evidence e, By by, Needs needs = Needs::nothing, const char* reason = "") {
    rows.push_back({rule, std::move(e), by, needs, reason});
  };
  Evidence tilted = with(featureAnswer(30));
  tilted.tilted = "source map is tilted 5.0 +- 0.1 deg";
  add("a tilted map is refused before anything else", tilted, By::none, Needs::nothing, "source map is tilted");
  add("a strong feature winner stands alone", with(featureAnswer(30, 2)), By::features);
  Evidence thin = with(featureAnswer(2));
  thin.wide.reset();
  add("too few agreeing slice pairs: the wide search is asked first", thin, By::none, Needs::wide_search);
  add("... then, where it did not confirm them, the dense search", with(featureAnswer(2)), By::none,
      Needs::search_at_grid);
  Evidence confirmed = thinWith(search(landed(1300), 1000, true, 0.2));
  add("... a wide search whose best pose is the features' and leads 1.3x: the features' landing is asked", confirmed,
      By::none, Needs::features_landed);
  confirmed.features_landed = landed(1400);
  add("... and the features' answer stands where it lands more telling cells", confirmed, By::features);
  confirmed.features_landed = landed(1200);
  add("... the wide search's pose where that lands more", confirmed, By::wide);
  DensePose partial = landed(1300);
  partial.support = 1;  // a 30 % crop: 1 slice lands half of all its cells, 6 half of those the other map saw
  partial.support_seen = 6;
  Evidence crop = thinWith(search(partial, 1000, true, 0.2));
  crop.features_landed = landed(1400);
  add("... its slices judged on the cells that land where the other map saw anything", crop, By::features);
  Evidence elsewhere = thinWith(search(landed(1300), 1000, false, 0.2));
  add("a wide search whose best pose is elsewhere: the features' landing is asked", elsewhere, By::none,
      Needs::features_landed);
  // The wide search's coarse raster can miss the features' pose (kitti crops).
  Evidence missed = elsewhere;
  missed.features_landed = landed(2000);
  add("... where that lands 1.5x its best pose's, the poses around it are asked", missed, By::none,
      Needs::around_features);
  missed.around_features = landed(1500);
  add("... and the features' answer stands where it lands more than any of those, beyond chance", missed, By::features);
  missed.around_features = landed(1950);
  add("... and not where one lands within chance of it (0.8 sigma)", missed, By::none, Needs::search_at_grid);
  missed.at_grid = DenseEvidence{};
  add("... a refusal that says so", missed, By::none, Needs::nothing,
      "only 1 slice pairs agree (need 3); a search on a raster twice as fine did not confirm it (its best pose lies "
      "2.50 m, 0.0 deg and 0.00 m in height away); the features' pose lands 2000 telling cells, one 0.00 m from it "
      "1950 (0.8 sigma beyond chance, need 3): the occupancy does not pin it down");
  Evidence landed_thin = elsewhere;
  landed_thin.features_landed = landed(2000, 0, 2);
  add("a features' landing over 2 slices does not outscore the wide search's pose", landed_thin, By::none,
      Needs::search_at_grid);
  Evidence short_lead = elsewhere;
  short_lead.features_landed = landed(1700);
  add("nor one landing 1.3x as much as it", short_lead, By::none, Needs::search_at_grid);
  elsewhere.features_landed = landed(1000);
  add("a features' pose landing less than the wide search's best: the dense search is asked", elsewhere, By::none,
      Needs::search_at_grid);
  Evidence chance = thinWith(search(landed(130), 100, true, 0.2));
  add("a wide lead of 130 to 100 is chance (1.9 sigma): not confirmed", chance, By::none, Needs::search_at_grid);
  Evidence two = thinWith(search(landed(1300, 0, 2), 1000, true, 0.2));
  two.features_landed = landed(1400);
  add("a wide best pose over 2 slices confirms (kitti-lidar-16: 2.05x over 2 slices)", two, By::features);
  Evidence few = thinWith(search(landed(1300, 0, 1), 1000, true, 0.2));
  add("a wide best pose over 1 slice does not confirm", few, By::none, Needs::search_at_grid);
  // A refusal names what the wide search fell short of (LiDAR crops, too
  // large for the dense search, said only "only 2 slice pairs agree").
  few.at_grid = DenseEvidence{};
  add("... and the refusal says so", few, By::none, Needs::nothing,
      "only 1 slice pairs agree (need 3); a search on a raster twice as fine did not confirm it (lead 1.30x; over 1 "
      "slices, need 2)");
  chance.at_grid = DenseEvidence{};
  add("... or that its lead is chance", chance, By::none, Needs::nothing,
      "only 1 slice pairs agree (need 3); a search on a raster twice as fine did not confirm it (lead 1.30x; 2.0 "
      "sigma beyond chance, need 3)");
  elsewhere.at_grid = DenseEvidence{};
  add("... or where its best pose lies, and how the features' own pose landed against it", elsewhere, By::none,
      Needs::nothing,
      "only 1 slice pairs agree (need 3); a search on a raster twice as fine did not confirm it (its best pose lies "
      "2.50 m, 0.0 deg and 0.00 m in height away); the features' pose lands 1000 telling cells, that pose 1300 (lead "
      "0.77x, need 1.40x; -6.3 sigma beyond chance, need 3)");
  add("a weak winner: the dense search is asked", with(featureAnswer(10, 2)), By::none, Needs::search_at_grid);
  add("two answers within min_support pairs are ambiguous", with(featureAnswer(6, 4), DenseEvidence{}, 0.2), By::none,
      Needs::nothing, "ambiguous: another answer 12");
  add("a winner under 1.25x its runner-up is ambiguous", with(featureAnswer(30, 25), DenseEvidence{}, 0.2), By::none,
      Needs::nothing, "ambiguous");
  add("too few inliers, and no search confirms them", with(few_inliers, DenseEvidence{}, 0.2), By::none, Needs::nothing,
      "only 10 inlier correspondences (need 20)");
  Evidence few_unchecked = with(few_inliers);
  few_unchecked.wide.reset();
  add("a clear winner on too few inliers is checked wide like a thin one (kitti-lidar-268: 15)", few_unchecked,
      By::none, Needs::wide_search);
  Evidence few_confirmed = with(few_inliers);
  few_confirmed.wide = search(landed(1300), 1000, true, 0.2);
  few_confirmed.features_landed = landed(1400);
  add("... and answers where it confirms them", few_confirmed, By::features);
  Evidence ambiguous_few = with(featureAnswer(6, 4));
  ambiguous_few.features.inliers = 10;
  ambiguous_few.wide.reset();
  add("an ambiguous winner is checked wide like a thin one (kitti-lidar-16: 3 vs 1)", ambiguous_few, By::none,
      Needs::wide_search);
  Evidence ambiguous_confirmed = with(featureAnswer(6, 4));
  ambiguous_confirmed.wide = search(landed(1300), 1000, true, 0.2);
  ambiguous_confirmed.features_landed = landed(1400);
  add("... and answers where it confirms it", ambiguous_confirmed, By::features);
  add("no dense search possible (large map): a weak winner stands", with(featureAnswer(10, 2), DenseEvidence{}),
      By::features);
  add("no dense search possible, no feature answer: refused", with(none_found, DenseEvidence{}), By::none,
      Needs::nothing, "no slice pair produced an estimate");
  add("the dense search confirms: its best pose is the features' and leads 1.3x",
      with(featureAnswer(10, 2), search(landed(1300), 1000, true)), By::features);
  add("a clear dense pose elsewhere (1.5x) replaces the features' answer",
      with(featureAnswer(10, 2), search(landed(1500), 1000, false)), By::at_grid);
  add("a dense pose elsewhere at 1.3x: the two disagree, then the pooled search is asked",
      with(featureAnswer(10, 2), search(landed(1300), 1000, false)), By::none, Needs::pooled_search);
  add("the same at a 0.2 m grid (no pooled search): refused as disagreeing",
      with(featureAnswer(10, 2), search(landed(1300), 1000, false, 0.2), 0.2), By::none, Needs::nothing,
      "the features and a dense search of the occupancy disagree (1.30x lead for a pose 2.50 m");
  add("a dense search too close to tell (1.1x) does not confirm",
      with(featureAnswer(10, 2), search(landed(1100), 1000, true, 0.2), 0.2), By::none, Needs::nothing,
      "a dense search of the occupancy does not confirm the features' answer (its best pose: lead 1.10x, need 1.20x; "
      "2.2 "
      "sigma beyond chance, need 3)");
  add("a lead on a handful of cells is chance: 13 to 7 (1.86x) is no answer",
      with(featureAnswer(1), search(landed(13), 7, false, 0.2), 0.2), By::none, Needs::nothing,
      "only 1 slice pairs agree (need 3); nor did a dense search");
  add("... and the refusal says which bar refused it: a lead past 1.4x that chance explains",
      with(featureAnswer(1), search(landed(29), 20, false, 0.2), 0.2), By::none, Needs::nothing,
      "only 1 slice pairs agree (need 3); nor did a dense search of the occupancy find a clear pose (lead 1.45x; 1.3 "
      "sigma beyond chance, need 3)");
  add("a dense best pose on too few slices does not answer",
      with(featureAnswer(1), search(landed(2000, 0, 2), 1000, false, 0.2), 0.2), By::none, Needs::nothing,
      "only 1 slice pairs agree (need 3); nor did a dense search of the occupancy find a clear pose (lead 2.00x; over "
      "2 slices, need 3)");
  add("a refused feature match is answered by a clear dense pose", with(featureAnswer(1), search(landed(2000), 1000)),
      By::at_grid);
  Evidence unlooked = with(featureAnswer(1), search(landed(2000), 1000));
  unlooked.second_look.reset();
  add("a dense pose that would answer: a second look, the maps' roles swapped, is asked", unlooked, By::at_grid,
      Needs::second_look);
  Evidence near = with(featureAnswer(1), search(landed(2000), 1000));
  near.second_look = lookedAgain(0.6);
  add("... it answers where that puts the source's origin within sqrt(2) x 5 cells (0.71 m at g 0.1)", near,
      By::at_grid);
  Evidence far = with(featureAnswer(1), search(landed(2000), 1000, false, 0.05), 0.05);
  far.second_look = lookedAgain(0.41);
  add("... and is refused where farther (sunrgbd-room-156 at g 0.05: 0.41 m, 0.51 m off)", far, By::none,
      Needs::nothing,
      "a dense search's pose was not found again with the maps' roles swapped: that search puts the source's frame "
      "origin 0.41 m from it (within 0.35 m: two looks, each within 5 cells)");
  Evidence lost = with(featureAnswer(1), search(landed(2000), 1000));
  lost.second_look->same_place = false;
  add("... or where the second look's best pose lies elsewhere", lost, By::none, Needs::nothing,
      "a dense search's pose was not found again with the maps' roles swapped: that search's best pose lies elsewhere");
  Evidence wide_unlooked = thinWith(search(landed(1300), 1000, true, 0.2));
  wide_unlooked.features_landed = landed(1200);
  wide_unlooked.second_look.reset();
  add("the wide search's pose needs none: the features' answer was its second look", wide_unlooked, By::wide);
  add("a dense best pose that contradicts the empty space: the features' own landing is asked",
      with(featureAnswer(10, 2), search(landed(1000, 600), 100)), By::none, Needs::features_landed);

  Evidence own_holds = with(featureAnswer(10, 2), search(landed(1000, 600), 100));
  own_holds.features_landed = landed(15000, 300);
  add("... and the features' answer stands where its own landing holds (2 %)", own_holds, By::features);
  Evidence own_fails = with(featureAnswer(10, 2), search(landed(1000, 600), 100), 0.2);
  own_fails.features_landed = landed(7000, 5000);
  add("... and is refused where its own landing contradicts (71 %)", own_fails, By::none, Needs::nothing,
      "a dense search of the occupancy does not confirm the features' answer (its best pose: lead 0.00x, need 1.20x");

  Evidence pooled_clear = with(featureAnswer(1), search(landed(1200), 1000), 0.05);
  pooled_clear.pooled = search(landed(900), 300, false, 0.1);
  add("the pooled search answers with a clear pose of its own", pooled_clear, By::pooled);
  // A grid pose 1.96x ahead over 1 slice: too few to answer, enough to outweigh a pooled pose elsewhere.
  Evidence disputed = with(featureAnswer(1), search(landed(417, 0, 1), 213), 0.05);
  disputed.pooled = search(landed(133), 82, false, 0.1);
  add("... but not where the grid's best pose, holding over too few slices, leads 1.4x elsewhere "
      "(sunrgbd-room-200: 1.36 m off)",
      disputed, By::none, Needs::nothing,
      "only 1 slice pairs agree (need 3); nor did a dense search of the occupancy find a clear pose (lead 1.96x; over "
      "1 slices, need 3); at 0.10 m cells its best pose leads 1.62x but lies elsewhere than the map's grid's best "
      "pose, 1.96x ahead over 1 slices");
  Evidence undisputed = disputed;
  undisputed.pooled->at_grid_best = true;
  add("... and answers where that pose is its own", undisputed, By::pooled);
  Evidence agreeing = with(featureAnswer(1), search(landed(1250), 1000), 0.05);
  agreeing.pooled = search(landed(1150), 1000, false, 0.1);
  add("grid (1.25x) and pooled (1.15x) short of a clear pose refuse, on one pose or not", agreeing, By::none,
      Needs::nothing,
      "only 1 slice pairs agree (need 3); nor did a dense search of the occupancy find a clear pose (lead 1.25x, "
      "need 1.40x); at 0.10 m cells its best pose: lead 1.15x, need 1.40x");
  Evidence pooled_chance = with(featureAnswer(1), search(landed(74), 59, false, 0.1), 0.1);
  pooled_chance.pooled = search(landed(13), 7, false, 0.2);
  add("a pooled lead on 13 cells against 7 is chance (the real RGB-D room answered 13.9 m off)", pooled_chance,
      By::none, Needs::nothing, "only 1 slice pairs agree");

  for (const Row& row : rows) {
    SCOPED_TRACE(row.rule);
    const Verdict v = decideMatch(row.evidence, params);
    EXPECT_EQ(v.by, row.by);
    EXPECT_EQ(v.needs, row.needs);
    if (row.by == By::none && row.needs == Needs::nothing) {
      EXPECT_EQ(v.reason.rfind(row.reason, 0), 0u) << v.reason;
    } else {
      EXPECT_TRUE(v.reason.empty()) << v.reason;
    }
  }
}

TEST(Verdict, PoseEvidence) {
  EXPECT_DOUBLE_EQ(contradiction(landed(100, 20)), 0.2);
  EXPECT_TRUE(consistent(landed(100, 20)));
  EXPECT_FALSE(consistent(landed(100, 21)));
  EXPECT_TRUE(holdsOver(landed(100, 0, 3), 3));
  EXPECT_FALSE(holdsOver(landed(100, 0, 2), 3));
  EXPECT_NEAR(significance(13, 7), 6 / std::sqrt(20.0), 1e-12);
  EXPECT_DOUBLE_EQ(significance(-5, 0), 0);
  EXPECT_NEAR(search(landed(1300), 1000).lead(), 1.3, 1e-12);
  EXPECT_DOUBLE_EQ(search(landed(100, 60), 10).lead(), 0) << "a best pose that contradicts more than it finds";
}
