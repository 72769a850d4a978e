#pragma once
// Human-readable and JSON renderings of a match result.
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>

#include "core/matcher.hpp"

namespace tomomap::cli {

/// Error of an estimate against ground truth, with the paper's success rule.
struct GroundTruthCheck {
  Pose4 expected;
  PoseError error;
  double translation_limit = 0;  ///< 5 x grid [m]
  double yaw_limit = 0;          ///< 10 degrees [rad]
  bool success() const { return error.translation < translation_limit && error.yaw < yaw_limit; }
};

GroundTruthCheck checkAgainstGroundTruth(const MatchResult& r, const Eigen::Matrix4d& P_target,
                                         const Eigen::Matrix4d& P_source, double grid);

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
};

/// Prints the result (and its error against ground truth when both poses are
/// given), writes the JSON when asked, and returns the exit code.
int report(const MatchResult& r, const std::optional<Eigen::Matrix4d>& P_target,
           const std::optional<Eigen::Matrix4d>& P_source, double grid, const ReportOptions& how,
           const nlohmann::json& extra = {});

/// One line: the transform, or "no reliable match: REASON".
std::string resultLine(const MatchResult& r);

/// Throws InputError unless both ground-truth options or neither are given.
void requireBothOrNeither(const std::string& gt_target, const std::string& gt_source);

}  // namespace tomomap::cli
