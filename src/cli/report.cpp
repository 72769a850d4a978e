#include "report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>

#include "exit_codes.hpp"
#include "results/agreed_transform.hpp"
#include "results/json_schema.hpp"
#include "version.hpp"

namespace tomomap::cli {
namespace {

template <typename... Args>
std::string format(const char* fmt, Args... args) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

std::string tiltText(double tilt) { return tilt < 0 ? "not measurable" : format("%.1f deg", degrees(tilt)); }

nlohmann::json tiltJson(double tilt) { return tilt < 0 ? nlohmann::json() : nlohmann::json(degrees(tilt)); }

}  // namespace

Points sourceSample(const Points& source) {
  const size_t stride = std::max<size_t>(1, (source.size() + kErrorSamplePoints - 1) / kErrorSamplePoints);
  Points sample;
  for (size_t i = 0; i < source.size(); i += stride) sample.push_back(source[i]);
  return sample;
}

GroundTruthCheck checkAgainstGroundTruth(const MatchResult& r, const GroundTruth& truth, double grid) {
  return checkAgainstGroundTruth(r.matrix(), truth, grid);
}

GroundTruthCheck checkAgainstGroundTruth(const Eigen::Matrix4d& estimate, const GroundTruth& truth, double grid) {
  GroundTruthCheck c;
  const Eigen::Matrix4d expected = truth.P_target * truth.P_source.inverse();
  c.expected = expected;
  // Whole matrices: with a levelled map the answer is no longer 4-DoF, and the
  // rotation error is then the full angle between the two rotations.
  const Eigen::Matrix4d miss = estimate - expected;  // (E - G) p: how far E puts p from where G does
  c.at_origin = miss.topRightCorner<3, 1>().norm();
  double squares = 0;
  for (const auto& p : truth.source_sample) squares += (miss * p.cast<double>().homogeneous()).squaredNorm();
  c.error.translation =
      truth.source_sample.empty() ? c.at_origin : std::sqrt(squares / static_cast<double>(truth.source_sample.size()));
  c.error.yaw =
      Eigen::AngleAxisd(Eigen::Matrix3d(estimate.topLeftCorner<3, 3>().transpose() * expected.topLeftCorner<3, 3>()))
          .angle();
  c.translation_limit = 5.0 * grid;
  c.yaw_limit = radians(10.0);
  return c;
}

std::string resultLine(const MatchResult& r) {
  const auto& T = r.T_target_source;
  if (!r.reliable) return "no reliable match: " + r.reason;
  return format("T_target_source  x %.4f  y %.4f  z %.4f m  yaw %.4f rad (%.2f deg)", T.x, T.y, T.z, T.yaw,
                degrees(T.yaw));
}

void printResult(std::ostream& out, const MatchResult& r, const std::optional<GroundTruthCheck>& gt,
                 const std::string& method) {
  out << resultLine(r) << "\n";
  if (r.reliable) {
    if (r.T_target_source_6dof) out << "  its 4-DoF part; the whole transform between the maps' own frames:\n";
    const Eigen::Matrix4d M = r.matrix();
    for (int i = 0; i < 4; ++i) out << format("  [%9.5f %9.5f %9.5f %9.4f]\n", M(i, 0), M(i, 1), M(i, 2), M(i, 3));
  }
  if (method == "fpfh-ransac") {
    out << format("keypoints        target %zu, source %zu, %zu inliers\n", r.target_features, r.source_features,
                  r.features.inliers);
    out << format("time             %.3f s: normals + FPFH %.3f, RANSAC %.3f\n", r.timings.total(), r.timings.features,
                  r.timings.pair_matching);
  } else {
    if (r.reliable)
      out << format("answered by      %s, %.1f sigma clear of the best answer elsewhere\n", fromName(r.answered_by),
                    r.lead_sigma);
    const FeatureFindings& f = r.features;
    if (f.support > 0)
      out << format(
          "features         %d slice pairs agree (runner-up %d), %zu inliers, spread x %.2f y %.2f z %.2f m\n",
          f.support, f.runner_up_support, f.inliers, f.inlier_spread.x(), f.inlier_spread.y(), f.inlier_spread.z());
    const DenseFindings& d = r.dense;
    if (d.at_grid_lead > 0)
      out << format("dense search     at the map's cells its best pose leads the next by %.2fx\n", d.at_grid_lead);
    if (d.pooled_lead > 0)
      out << format("                 on occupancy pooled to twice the cell: %.2fx\n", d.pooled_lead);
    if (d.wide_lead > 0)
      out << format("                 on a raster twice as fine, over its next or a candidate elsewhere: %.2fx\n",
                    d.wide_lead);
    if (d.second_look_apart)
      out << format("                 with the maps' roles swapped, the source's origin %.3f m from its pose\n",
                    *d.second_look_apart);
    out << "tilt             target " << tiltText(r.target_tilt) << ", source " << tiltText(r.source_tilt) << "\n";
    if (r.finish && r.finish->held)
      out << format(
          "6-DoF finish     corrected %.2f deg of roll and pitch, moved the source %.3f m; %.0f %% of its "
          "cells on the target's surfaces (%.0f %% before)\n",
          degrees(r.finish->roll_pitch_corrected), r.finish->moved, 100 * r.finish->seen_found_after,
          100 * r.finish->seen_found_before);
    else if (r.finish)
      out << "6-DoF finish     kept the 4-DoF answer: " << r.finish->why_not << "\n";
    out << format(
        "slices           target %d (%zu features), source %d (%zu features), %zu of %zu slice pairs matched\n",
        r.target_slices, r.target_features, r.source_slices, r.source_features, r.features.slice_pairs,
        r.features.slice_pairs_total);
    const auto& t = r.timings;
    out << format(
        "time             %.3f s: load %.3f, voxel %.3f, slicing %.3f, features %.3f, pair matching %.3f, "
        "consensus %.3f, refinement %.3f, dense search %.3f, 6-DoF finish %.3f\n",
        t.total(), t.load, t.voxel, t.slicing, t.features, t.pair_matching, t.consensus, t.refinement, t.dense,
        t.finish);
  }
  if (gt) {
    const Pose4 e = Pose4::fromMatrix(gt->expected);
    out << format("ground truth     x %.4f  y %.4f  z %.4f m  yaw %.4f rad\n", e.x, e.y, e.z, e.yaw);
    if (r.reliable)
      out << format(
          "error            translation %.4f m over the source's points (limit %.3f; %.4f m at its origin), "
          "rotation %.4f rad (limit %.4f): %s\n",
          gt->error.translation, gt->translation_limit, gt->at_origin, gt->error.yaw, gt->yaw_limit,
          gt->success() ? "success" : "FAILURE");
  }
}

nlohmann::json toJson(const MatchResult& r, const std::optional<GroundTruthCheck>& gt) {
  nlohmann::json j;
  j["reliable"] = r.reliable;
  if (r.reliable) {
    j["T_target_source"] = tomomap::toJson(r.T_target_source);
    if (r.T_target_source_6dof) j["T_target_source_6dof"] = matrixJson(*r.T_target_source_6dof);
  } else {
    j["reason"] = r.reason;
  }
  j["tilt_deg"] = {{"target", tiltJson(r.target_tilt)}, {"source", tiltJson(r.source_tilt)}};
  if (r.finish) {
    const SixDofFinish& f = *r.finish;
    j["finish"] = {{"held", f.held},
                   {"roll_pitch_corrected_deg", degrees(f.roll_pitch_corrected)},
                   {"moved_m", f.moved},
                   {"rms_m", {f.rms_before, f.rms_after}},
                   {"on_surface", {f.seen_found_before, f.seen_found_after}},
                   {"iterations", f.iterations}};
    if (!f.held) j["finish"]["why_not"] = f.why_not;
  } else {
    j["finish"] = nullptr;
  }
  if (r.reliable) {
    j["answered_by"] = fromName(r.answered_by);
    j["lead_sigma"] = r.lead_sigma;
    j["height_offset_slices"] = r.height_offset;
  }
  const FeatureFindings& f = r.features;
  j["features"] = {{"support", f.support},
                   {"height_offset_slices", f.height_offset},
                   {"runner_up_support", f.runner_up_support},
                   {"runner_up_offset_slices", f.runner_up_offset},
                   {"inliers", f.inliers},
                   {"inlier_spread", {f.inlier_spread.x(), f.inlier_spread.y(), f.inlier_spread.z()}}};
  const DenseFindings& d = r.dense;
  j["dense"] = {{"at_grid_lead", d.at_grid_lead},
                {"wide_lead", d.wide_lead},
                {"pooled_lead", d.pooled_lead},
                {"second_look_m", d.second_look_apart ? nlohmann::json(*d.second_look_apart) : nlohmann::json()}};
  j["slices"] = {{"target", r.target_slices},
                 {"source", r.source_slices},
                 {"pairs", f.slice_pairs},
                 {"pairs_total", f.slice_pairs_total},
                 {"target_features", r.target_features},
                 {"source_features", r.source_features}};
  const auto& t = r.timings;
  j["timings_s"] = {{"load", t.load},
                    {"voxel", t.voxel},
                    {"slicing", t.slicing},
                    {"features", t.features},
                    {"pair_matching", t.pair_matching},
                    {"consensus", t.consensus},
                    {"refinement", t.refinement},
                    {"dense", t.dense},
                    {"finish", t.finish},
                    {"total", t.total()}};
  if (gt) {
    j["ground_truth"] = tomomap::toJson(Pose4::fromMatrix(gt->expected));
    j["ground_truth"]["matrix"] = matrixJson(gt->expected);
    if (r.reliable)
      j["error"] = {{"translation", gt->error.translation},
                    {"translation_at_origin", gt->at_origin},
                    {"yaw", gt->error.yaw},
                    {"success", gt->success()}};
  }
  return j;
}

namespace {

/// Each candidate's check against the ground truth, where there is one.
std::vector<std::optional<GroundTruthCheck>> candidateChecks(const MatchResult& r,
                                                             const std::optional<GroundTruth>& truth, double grid) {
  std::vector<std::optional<GroundTruthCheck>> out(r.candidates.size());
  if (truth)
    for (size_t i = 0; i < out.size(); ++i)
      out[i] = checkAgainstGroundTruth(r.candidates[i].T_own_frames, *truth, grid);
  return out;
}

/// A candidate's error against the truth, as `error` is for the answer (without its origin error).
nlohmann::json candidateErrorJson(const GroundTruthCheck& check) {
  return {{"translation", check.error.translation}, {"yaw", check.error.yaw}, {"success", check.success()}};
}

/// The same in the candidates' text lines.
std::string candidateErrorText(const GroundTruthCheck& check) {
  return format("error %.3f m, %.4f rad: %s", check.error.translation, check.error.yaw,
                check.success() ? "right" : "wrong");
}

nlohmann::json landedJson(const DensePose& p) {
  return {{"x", p.transform.t.x()},
          {"y", p.transform.t.y()},
          {"yaw", p.transform.yaw},
          {"height_offset_slices", p.offset},
          {"score", p.score()},
          {"telling_cells", p.telling_inliers},
          {"contradicted_cells", p.contradicted},
          {"slices", p.support},
          {"slices_seen", p.support_seen}};
}

/// A landing slice by slice, the slices with cells: [slice, cells, telling, seen, on, telling_on, contradicted].
nlohmann::json slicesJson(const std::vector<SliceLanding>& slices) {
  nlohmann::json out = nlohmann::json::array();
  for (const SliceLanding& s : slices)
    if (s.cells > 0) out.push_back({s.slice, s.cells, s.telling, s.seen, s.on, s.telling_on, s.contradicted});
  return out;
}

nlohmann::json candidatesJson(const MatchResult& r, const std::vector<std::optional<GroundTruthCheck>>& checks) {
  nlohmann::json out = nlohmann::json::array();
  for (size_t i = 0; i < r.candidates.size(); ++i) {
    const Candidate& c = r.candidates[i];
    nlohmann::json j{{"from", fromName(c.from)},
                     {"rank", c.rank},
                     {"feature_support", c.feature_support},
                     {"proposed", landedJson(c.proposed_landed)},
                     {"refined", landedJson(c.landed)}};
    j["slices"] = slicesJson(c.slices);
    if (!c.pooled_slices.empty()) j["pooled_slices"] = slicesJson(c.pooled_slices);
    if (!c.feature_votes.empty()) {
      nlohmann::json votes = nlohmann::json::array();
      for (size_t k = 0; k < c.feature_votes.size(); ++k)
        if (c.feature_votes[k] > 0) votes.push_back({k, c.feature_votes[k]});
      j["feature_votes"] = votes;
    }
    if (checks[i]) j["error"] = candidateErrorJson(*checks[i]);
    out.push_back(j);
  }
  return out;
}

/// The candidates, best refined score first: where each came from, its score
/// as proposed and refined, and its error where the truth is known.
void listCandidates(std::ostream& out, const MatchResult& r,
                    const std::vector<std::optional<GroundTruthCheck>>& checks) {
  std::vector<size_t> order(r.candidates.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return r.candidates[a].landed.score() > r.candidates[b].landed.score(); });
  out << "candidates       " << r.candidates.size()
      << ", best refined score first: from (rank), score proposed -> refined, slices (where the target saw "
         "anything), contradicted cells\n";
  for (size_t i : order) {
    const Candidate& c = r.candidates[i];
    out << format("  %-15s (%d) %9.0f -> %9.0f  %3d (%3d)  %6zu", fromName(c.from), c.rank, c.proposed_landed.score(),
                  c.landed.score(), c.landed.support, c.landed.support_seen, c.landed.contradicted);
    if (checks[i]) out << "  " << candidateErrorText(*checks[i]);
    out << "\n";
  }
}

/// What the decision over the candidates said: the candidate it answered
/// and what it answered on, or why it has none.
void printDecision(std::ostream& out, const MatchResult& r) {
  const CandidateVerdict& v = *r.candidate_verdict;
  if (v.answer < 0)
    out << "decision         no reliable match: " << v.reason << "\n";
  else
    out << format("decision         candidate %s (%d), %.1f sigma clear on %s over %d slices\n",
                  fromName(r.candidates[static_cast<size_t>(v.answer)].from),
                  r.candidates[static_cast<size_t>(v.answer)].rank, v.lead_sigma, onName(v.on), v.slices);
}

}  // namespace

int report(const MatchResult& r, const std::optional<GroundTruth>& truth, double grid, const ReportOptions& how,
           const nlohmann::json& extra) {
  std::optional<GroundTruthCheck> gt;
  if (truth) gt = checkAgainstGroundTruth(r, *truth, grid);
  const std::vector<std::optional<GroundTruthCheck>> checks = candidateChecks(r, truth, grid);
  const bool json_to_stdout = how.json == "-";
  std::ostream& text = json_to_stdout ? std::cerr : std::cout;
  if (how.quiet)
    text << resultLine(r) << "\n";
  else
    printResult(text, r, gt, how.method);
  if (!how.quiet && how.candidates && !r.candidates.empty()) listCandidates(text, r, checks);
  if (!how.quiet && r.candidate_verdict) printDecision(text, r);
  if (!how.json.empty()) {
    auto j = toJson(r, gt);
    j["schema_version"] = kJsonSchemaVersion;
    j["tool"] = {{"name", how.method == "tomomap" ? "tomomap" : "tomomap-baseline"}, {"version", TOMOMAP_VERSION}};
    j["method"] = how.method;
    j["grid"] = grid;
    if (extra.is_object()) j.update(extra);
    if (how.candidates && !r.candidates.empty()) j["candidates"] = candidatesJson(r, checks);
    if (r.candidate_verdict) {
      const CandidateVerdict& v = *r.candidate_verdict;
      j["candidate_decision"] = {{"answer", v.answer >= 0 ? nlohmann::json(v.answer) : nlohmann::json()},
                                 {"on", onName(v.on)},
                                 {"lead_sigma", v.lead_sigma},
                                 {"slices", v.slices},
                                 {"compared_at", {v.compared_at.x(), v.compared_at.y()}}};
      if (v.answer < 0) j["candidate_decision"]["reason"] = v.reason;
    }
    if (json_to_stdout) {
      std::cout << j.dump(2) << "\n";
    } else {
      std::ofstream out(how.json);
      out << j.dump(2) << "\n";
      if (!out) throw InputError(how.json + ": cannot write JSON result");
    }
  }
  return r.reliable ? kExitOk : kExitNoMatch;
}

void requireBothOrNeither(const std::string& gt_target, const std::string& gt_source) {
  if (gt_target.empty() != gt_source.empty()) throw InputError("--gt-target and --gt-source go together");
}

}  // namespace tomomap::cli
