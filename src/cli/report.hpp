#pragma once
// Human-readable and JSON renderings of a match result.
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>

#include "core/matcher.hpp"

namespace tomomap::cli {

/// What an answer is checked against: the maps' ground-truth poses (world ->
/// map, so that T_target_source = P_target * P_source^-1) and where the
/// source's points lie.
struct GroundTruth {
  Eigen::Matrix4d P_target = Eigen::Matrix4d::Identity(), P_source = Eigen::Matrix4d::Identity();
  /// The source map's points, a sample (sourceSample): an answer's error is
  /// measured over them, not at the source frame's origin, which may lie tens
  /// of metres from the map (a map moved away, or a robot that started far).
  Points source_sample;
};

/// Up to kErrorSamplePoints of `source`, evenly spread through it.
Points sourceSample(const Points& source);
constexpr size_t kErrorSamplePoints = 20000;

/// Error of an estimate against ground truth, with the paper's success rule.
struct GroundTruthCheck {
  Eigen::Matrix4d expected = Eigen::Matrix4d::Identity();  ///< the true T_target_source (6-DoF where maps lean)
  /// translation: how far the answer puts the source's points from where
  /// they belong, rms over the sample [m] (at the origin without one); yaw:
  /// the whole angle between the two rotations [rad].
  PoseError error;
  double at_origin = 0;          ///< the translation error at the source frame's origin [m]
  double translation_limit = 0;  ///< 5 x grid [m]
  double yaw_limit = 0;          ///< 10 degrees [rad]
  bool success() const { return error.translation < translation_limit && error.yaw < yaw_limit; }
};

GroundTruthCheck checkAgainstGroundTruth(const MatchResult& r, const GroundTruth& truth, double grid);
GroundTruthCheck checkAgainstGroundTruth(const Eigen::Matrix4d& estimate, const GroundTruth& truth, double grid);

/// `method` names what found `r`: "fpfh-ransac" prints keypoints instead of slices.
void printResult(std::ostream& out, const MatchResult& r, const std::optional<GroundTruthCheck>& gt,
                 const std::string& method = "tomomap");

nlohmann::json toJson(const MatchResult& r, const std::optional<GroundTruthCheck>& gt);

/// How a result is reported: `json` a file to write the JSON to ("-":
/// stdout, the text then goes to stderr), `quiet` the text as one line.
struct ReportOptions {
  std::string json;
  std::string method = "tomomap";  ///< tomomap, or a baseline's name (tomomap-baseline --method)
  bool quiet = false;
  bool candidates = false;  ///< list every candidate, as text and in the JSON (--candidates)
};

/// Prints the result (and its error against ground truth when both poses are
/// given), writes the JSON when asked, and returns the exit code.
int report(const MatchResult& r, const std::optional<GroundTruth>& truth, double grid, const ReportOptions& how,
           const nlohmann::json& extra = {});

/// One line: the transform, or "no reliable match: REASON".
std::string resultLine(const MatchResult& r);

/// Throws InputError unless both ground-truth options or neither are given.
void requireBothOrNeither(const std::string& gt_target, const std::string& gt_source);

}  // namespace tomomap::cli
