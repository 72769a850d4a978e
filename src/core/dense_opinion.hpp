#pragma once
// The evidence the verdict asks for beyond the features (verdict.hpp): the
// dense searches of small maps (dense_search.hpp), and the answer taken from
// the search the verdict names.
#include "matcher.hpp"
#include "verdict.hpp"

namespace tomomap {

/// Settles `r` (matchFeatures' figures from the features, `e` their evidence)
/// on the verdict: gathers what decideMatch asks for (the dense search at the
/// maps' grid, the features' answer landed, the search on occupancy pooled to
/// twice the cell, a second look at the pose that would answer), records each
/// search's figures in `r`, and answers from the search the verdict names.
/// Small maps get this second opinion because few slices and a 31-pixel ORB
/// patch spanning most of the image leave the tomographic match refusing or,
/// with noisy walls, fooled by a half-turned room or by one enclosure laid on a
/// similar one, while the occupancy itself still tells the right pose apart.
/// Whatever answers, a small map's answer then takes the height offset where
/// the occupancy meets best. Larger maps are not searched.
void settleMatch(MatchResult& r, Evidence& e, const MapFeatures& target, const MapFeatures& source,
                 const MatchParams& params);

}  // namespace tomomap
