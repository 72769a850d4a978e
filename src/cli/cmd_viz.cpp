// `tomomap viz TARGET SOURCE -o DIR`: matches two maps and draws what happened.
#include <filesystem>
#include <iostream>

#include "commands.hpp"
#include "core/text.hpp"
#include "match_files.hpp"
#include "viz/match_pictures.hpp"

namespace tomomap::cli {
namespace {

struct VizOptions {
  MatchFilesOptions files;
  std::string out = "viz-out";
  int pairs = 3;
};

int runViz(const VizOptions& o) {
  namespace fs = std::filesystem;
  std::error_code ec;  // checked before the work, so a typo costs no time
  fs::create_directories(o.out, ec);
  if (ec || !fs::is_directory(o.out)) throw InputError(o.out + ": cannot create the output folder: " + ec.message());
  MatchedFiles m = matchFiles(o.files);
  const MatchResult& r = m.result;
  const double g = o.files.params.grid;
  std::optional<GroundTruthCheck> gt;
  if (m.truth) gt = checkAgainstGroundTruth(r, *m.truth, g);
  const int code = report(r, m.truth, g, {o.files.json, "tomomap", o.files.quiet, o.files.candidates}, m.inputs);

  const auto& T = r.T_target_source;
  std::vector<std::string> caption{
      fs::path(o.files.source).filename().string() + " aligned onto " + fs::path(o.files.target).filename().string() +
          " (walls and other vertical structure, seen from above)",
      "T_target_source: x " + fixed(T.x, 3) + " m, y " + fixed(T.y, 3) + " m, z " + fixed(T.z, 3) + " m, yaw " +
          fixed(degrees(T.yaw), 2) + " deg;  " +
          (r.reliable ? std::string(fromName(r.answered_by)) + ", " + fixed(r.lead_sigma, 1) + " sigma clear; " : "") +
          "features: " + std::to_string(r.features.support) + " slice pairs, " + std::to_string(r.features.inliers) +
          " inliers"};
  if (!r.reliable) caption.push_back("NO RELIABLE MATCH (" + r.reason + "): showing the best candidate");
  if (gt)
    caption.push_back("against ground truth: " + fixed(gt->error.translation, 3) + " m, " +
                      fixed(degrees(gt->error.yaw), 3) + " deg (" + (gt->success() ? "success" : "FAILURE") + ")");

  const std::string overlay = (fs::path(o.out) / "overlay.png").string();
  const std::string slices = (fs::path(o.out) / "slice-pairs.png").string();
  viz::writePng(overlay, viz::drawOverlay(m.target.occupancy, m.source.occupancy, T, caption));
  viz::writePng(slices, viz::drawSlicePairs(m.target, m.source, r, o.pairs));
  std::cout << "pictures         " << overlay << ", " << slices << "\n";
  return code;
}

}  // namespace

Command addVizCommand(CLI::App& app) {
  auto o = std::make_shared<VizOptions>();
  CLI::App* sub = app.add_subcommand(
      "viz", "Match two maps and draw the result: top-down overlay and the winning slice pairs (PNG).");
  sub->add_option("TARGET", o->files.target, "target map (.pcd, .ply, .xyz/.txt/.csv, OctoMap .bt/.ot)")->required();
  sub->add_option("SOURCE", o->files.source, "source map")->required();
  sub->add_option("-o,--out", o->out, "output folder for overlay.png and slice-pairs.png")->capture_default_str();
  sub->add_option("--pairs", o->pairs, "slice pairs to draw (most inliers first)")
      ->capture_default_str()
      ->check(CLI::Range(1, 20));
  addMatchOptions(*sub, o->files);
  sub->footer("Exit codes: 0 reliable match, 1 no reliable match (pictures still drawn), 2 bad input, 3 internal.");
  return {sub, [o] { return runViz(*o); }};
}

}  // namespace tomomap::cli
