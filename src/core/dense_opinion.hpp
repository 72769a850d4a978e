#pragma once
// The dense search's second opinion on a small map's match (dense_search.hpp).
#include "matcher.hpp"

namespace tomomap {

/// Small maps get a second opinion that needs no features: on a room, few
/// slices and a 31-pixel ORB patch spanning most of the image leave the
/// tomographic match refusing or, with noisy walls, fooled by a half-turned
/// room or by one enclosure laid on a similar one, however far its winner
/// leads (15 slice pairs against 5), while the occupancy itself still tells
/// the right pose apart. A feature answer the dense search does not confirm is
/// refused, or replaced where the dense search clearly found another pose; so
/// is a refused one. Where the map's own grid leaves the pair refused, the
/// search is asked again on occupancy pooled to twice the cell, and the three
/// (features, grid, pooled) picking one pose answer too. Whatever answers,
/// the answer then takes the height offset where the occupancy meets best.
/// Larger maps are not searched. `r` is matchFeatures' answer from the
/// features, judged.
void consultDenseSearch(MatchResult& r, const MapFeatures& target, const MapFeatures& source,
                        const MatchParams& params);

}  // namespace tomomap
