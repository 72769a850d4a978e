#pragma once
// The features' distinct answers: their winner's rivals, each proposed as a
// candidate (candidates.hpp).
#include "height_offsets.hpp"

namespace tomomap {

/// Whether two answers are one: the same transform (consensus tolerances, at
/// the source's centre) within the smear of height offsets (kSmearSlices).
bool sameAnswer(const OffsetScore& a, const OffsetScore& b, const MatchParams& params, const Eigen::Vector2d& centre);

/// The features' distinct answers (every height offset's consensus groups;
/// those within the smear of offsets with the same transform are one), the
/// kMostRivals with most support, most first.
std::vector<OffsetScore> distinctAnswers(const SlicePairTable& table, const MapFeatures& target,
                                         const MapFeatures& source, const MatchParams& params);

}  // namespace tomomap
