#pragma once
// The paper's method as published (Unlu et al., its "Consensus" matcher):
// slices, ORB, a rigid 2D estimate per slice pair, the consensus of each
// height offset, and the offset with the most agreeing slice pairs. No
// decision: it answers whenever any slice pair gave an estimate, as the
// paper's code does. Evaluations run it beside tomomap to count the pairs
// the plain method answers right that tomomap refuses, and the ones it
// answers wrong.
//
// It is built from tomomap's own stages (docs/algorithm.md), so it differs
// from the paper's code only where those do: a slice is descriptive from
// (width + height) / 2 occupied cells (tomomap's own from a quarter), where
// the paper's code asks for width + height points, so it sees at least the
// slices the paper's would.
#include "core/matcher.hpp"

namespace tomomap::baseline {

/// Every slice pair matched (params.exhaustive is forced), maps neither
/// levelled nor refused for tilt. reliable = some slice pair gave an estimate.
MatchResult matchPaperConsensus(const Points& target, const Points& source, MatchParams params);

}  // namespace tomomap::baseline
