#pragma once
// Height cross-correlation of two tomographic feature stacks (Unlu et al.; docs/algorithm.md).
#include <optional>
#include <string>

#include "candidate_decision.hpp"
#include "candidates.hpp"
#include "match_params.hpp"
#include "rigid2d.hpp"
#include "six_dof_finish.hpp"
#include "slice_pairs.hpp"

namespace tomomap {

/// Wall-clock seconds per stage.
struct StageTimings {
  double load = 0;  ///< reading the map files (filled where they are read)
  double voxel = 0, slicing = 0, features = 0, pair_matching = 0, consensus = 0, refinement = 0, dense = 0;
  double finish = 0;  ///< the 6-DoF finish (six_dof_finish.hpp)
  double total() const {
    return load + voxel + slicing + features + pair_matching + consensus + refinement + dense + finish;
  }
  /// Takes the map-description stages (as describeMap fills them) and the load time from `d`.
  void takeDescription(const StageTimings& d) {
    load = d.load;
    voxel = d.voxel;
    slicing = d.slicing;
    features = d.features;
  }
};

/// One slice pair that agreed with the winning consensus.
struct SupportingPair {
  int target_slice = 0, source_slice = 0;  ///< slice indices within their maps
  uint32_t inliers = 0;                    ///< RANSAC inliers of that pair's own estimate
};

/// What the tomographic match found, whatever the decision made of it: each
/// field means the same whichever search answered.
struct FeatureFindings {
  int support = 0;                         ///< agreeing slice pairs behind the features' answer; 0: they had none
  int runner_up_support = 0;               ///< of their best other answer (height_offsets.hpp OffsetChoice)
  int runner_up_offset = 0;                ///< its height offset [slices]
  int height_offset = 0;                   ///< the features' answer's height offset [slices]
  std::vector<SupportingPair> supporters;  ///< the slice pairs behind `support`, most inliers first
  size_t inliers = 0;                      ///< feature correspondences consistent with their answer
  Eigen::Vector3d inlier_spread = Eigen::Vector3d::Zero();  ///< std. dev. of those inliers in target x, y, z [m]
  size_t slice_pairs = 0;           ///< slice pairs matched (all, or those the offset votes point to)
  size_t slice_pairs_total = 0;     ///< n_target x n_source slices with features
  size_t slice_pairs_recalled = 0;  ///< of slice_pairs, those a PairCache remembered instead of matched
};

/// What the dense searches of small maps found (dense_opinion.hpp), each
/// search's best pose over its next in DensePose::score (dense_search.hpp),
/// as the decision weighs it (weighedSearches); 0 where that search did not
/// run or found nothing.
struct DenseFindings {
  double at_grid_lead = 0;  ///< the search on the maps' own cells, full slices
  double wide_lead = 0;     ///< the search on a raster twice as fine (kWideCoarseSide)
  double pooled_lead = 0;   ///< the search on occupancy pooled to twice the cell
  /// Where the search whose pose would answer, asked again with the maps'
  /// roles swapped, put the source's frame origin, apart from that pose [m]
  /// (candidate_decision.hpp, SecondLook); unset where it was not asked or found none.
  std::optional<double> second_look_apart;
};

/// The answer to one match, then what each search found on the way.
struct MatchResult {
  /// False means "no reliable match": T_target_source is then meaningless and
  /// must not be used; `reason` says why.
  bool reliable = false;
  std::string reason;
  /// p_target = T_target_source * p_source (between the levelled frames, if
  /// levelled): the 4-DoF answer, or, where the 6-DoF finish held, the 4-DoF
  /// transform nearest it at the source map's centre (its yaw, and the centre
  /// moved where it moves it).
  Pose4 T_target_source;
  /// The whole transform between the maps' own frames, where it is not 4-DoF:
  /// a map was levelled (its levelling included), or the 6-DoF finish held
  /// (its roll and pitch included). Empty otherwise.
  std::optional<Eigen::Matrix4d> T_target_source_6dof;
  /// The 6-DoF finish of a reliable answer (six_dof_finish.hpp): what it
  /// corrected, or why it kept the 4-DoF answer. Empty where it did not run.
  std::optional<SixDofFinish> finish;
  /// The search whose pose is the answer (reliable only): the features
  /// (Candidate::From::features) or one of the dense searches.
  Candidate::From answered_by = Candidate::From::features;
  /// Target slice index - source slice index of the answer.
  int height_offset = 0;
  /// How clearly the evidence singles out the answer: the decision's lead
  /// (CandidateVerdict::lead_sigma) in normal sigmas. The fleet's pose graph
  /// weighs the pair by it. 0 when not reliable.
  double lead_sigma = 0;
  double target_tilt = 0, source_tilt = 0;  ///< as measured before any levelling [rad]; -1 = not measurable

  /// The transform to apply to source points to bring them into the target's frame.
  Eigen::Matrix4d matrix() const { return T_target_source_6dof.value_or(T_target_source.matrix()); }

  FeatureFindings features;
  DenseFindings dense;
  int target_slices = 0, source_slices = 0;
  size_t target_features = 0, source_features = 0;
  StageTimings timings;
  /// Every candidate pose the searches proposed, refined and landed
  /// (candidates.hpp); empty where the maps were refused before any search.
  std::vector<Candidate> candidates;
  /// The decision over them (candidate_decision.hpp), which is the answer;
  /// unset where a map was refused before any search (too tilted).
  std::optional<CandidateVerdict> candidate_verdict;
};

/// Finds T_target_source from two feature stacks of the same grid size: slice
/// pairs estimated (slice_pairs.hpp), height offsets scored and the best picked
/// (height_offsets.hpp) with their rivals (rival_answers.hpp), the winner
/// refined (refine.hpp); with the dense searches' poses (small maps), every
/// pose proposed is a candidate, and one decision over them answers
/// (dense_opinion.hpp, candidate_decision.hpp).
/// With a `cache` (pair_cache.hpp), the slice pairs it remembers from the
/// last match of these two maps are recalled, not matched again, and it then
/// remembers this match's: the answer is the same either way.
MatchResult matchFeatures(const MapFeatures& target, const MapFeatures& source, const MatchParams& params,
                          const Progress& progress = {}, PairCache* cache = nullptr);

/// Why a described map is too tilted to match (see MatchParams::max_tilt and
/// level), naming it by `role`; empty if it is fine.
std::optional<std::string> tiltRefusal(const MapFeatures& map, const std::string& role, const MatchParams& params);

/// A result that has only what the two maps' descriptions say: their slices,
/// features and tilts (no answer yet).
MatchResult resultFor(const MapFeatures& target, const MapFeatures& source);
/// Voxel filter, slicing, features and matching for two raw maps.
MatchResult matchMaps(const Points& target, const Points& source, const MatchParams& params,
                      const Progress& progress = {});

/// Voxel filter, slicing and features of one map, with the time each took and
/// (if asked) how many points the voxel filter kept. With `previous` (an
/// earlier version of this map, described with the same params), the map is
/// filtered on its cubes and sliced on its raster while it stays within them,
/// and the slices the change did not touch keep their features (kept_slices):
/// the same description as from scratch on that raster, ORB only where it changed.
/// With `up` (the map's up direction, known from an IMU or the SLAM), the
/// tilt is not estimated: the map is levelled by it wherever it leans.
MapFeatures describeMap(const Points& map, const MatchParams& params, StageTimings* timings = nullptr,
                        size_t* filtered_points = nullptr, const MapFeatures* previous = nullptr,
                        const std::optional<Eigen::Vector3d>& up = std::nullopt);

}  // namespace tomomap
