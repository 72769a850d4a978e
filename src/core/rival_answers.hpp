#pragma once
// A weak feature winner weighed against its rivals on the maps' occupancy.
#include <optional>

#include "height_offsets.hpp"

namespace tomomap {

/// What the occupancy decided among the features' answers.
struct LandedChoice {
  OffsetScore answer;     ///< the answer whose landing holds and outscores the rest
  int rival_support = 0;  ///< support of the best other answer whose landing also holds; 0 if none does
  int rival_offset = 0;   ///< its height offset [slices]
};

/// Whether two answers are one: the same transform (consensus tolerances, at
/// the source's centre) within the smear of height offsets (kSmearSlices).
bool sameAnswer(const OffsetScore& a, const OffsetScore& b, const MatchParams& params, const Eigen::Vector2d& centre);

/// The features' distinct answers (every height offset's consensus groups;
/// those within the smear of offsets with the same transform are one), the
/// kMostRivals with most support, most first.
std::vector<OffsetScore> distinctAnswers(const SlicePairTable& table, const MapFeatures& target,
                                         const MapFeatures& source, const MatchParams& params);

/// The features' distinct answers (every height offset's consensus groups;
/// those within the smear of offsets with the same transform are one), the
/// kMostRivals with most support, landed on both maps' occupancy as the dense
/// search lands its poses (dense_search.hpp). The answer whose landing holds
/// (verdict.hpp) and outscores every other beyond chance (kBars.significant),
/// if there is one. Where a building's rooms repeat along it, slice pairs
/// support a copy a room along as well as the right pose, often more; the copy
/// lands on walls where the other map saw empty space. Nothing where either
/// map is not dense-searchable (too large, or its occupancy partial: received
/// as features).
std::optional<LandedChoice> chooseByLanding(const SlicePairTable& table, const MapFeatures& target,
                                            const MapFeatures& source, const MatchParams& params);

}  // namespace tomomap
