// `tomomap match TARGET SOURCE`: offline registration of two map files.
#include <fstream>
#include <iostream>

#include "commands.hpp"
#include "core/map_io.hpp"
#include "baseline/fpfh_ransac.hpp"
#include "exit_codes.hpp"
#include "progress.hpp"
#include "report.hpp"

namespace tomomap::cli {
namespace {

struct MatchOptions {
  std::string target, source, json, gt_target, gt_source, method = "tomomap";
  MatchParams params;
  bool progress = false, quiet = false;
};

/// The FPFH + RANSAC baseline, reported in the same form (its description time
/// as "features", its RANSAC as "pair matching").
MatchResult matchBaseline(const Points& target, const Points& source, const MatchParams& params) {
  validateMap(target, "target map");
  validateMap(source, "source map");
  baseline::FpfhParams fp;
  fp.grid = params.grid;
  fp.threads = params.threads;
  const baseline::FpfhResult b = baseline::matchFpfhRansac(target, source, fp);
  MatchResult r;
  r.reliable = b.converged;
  if (!b.converged) r.reason = "FPFH-RANSAC did not converge";
  r.T_target_source = b.T_target_source;
  r.inliers = static_cast<size_t>(b.inlier_fraction * static_cast<double>(b.source_keypoints));
  r.target_features = b.target_keypoints;
  r.source_features = b.source_keypoints;
  r.timings.features = b.describe_seconds;
  r.timings.pair_matching = b.ransac_seconds;
  return r;
}

int runMatch(const MatchOptions& o) {
  // Read everything first, so that a bad file fails before any long work.
  const Points target = loadMap(o.target);
  const Points source = loadMap(o.source);
  std::optional<Eigen::Matrix4d> P_target, P_source;
  if (!o.gt_target.empty()) P_target = loadPoseFile(o.gt_target);
  if (!o.gt_source.empty()) P_source = loadPoseFile(o.gt_source);

  if (!o.quiet)
    std::cout << "target " << o.target << " (" << target.size() << " points)\nsource " << o.source << " ("
              << source.size() << " points)\ngrid " << o.params.grid << " m\n";
  const MatchResult r = o.method == "tomomap"
                            ? matchMaps(target, source, o.params, terminalProgress(o.progress || stderrIsTerminal()))
                            : matchBaseline(target, source, o.params);
  std::optional<GroundTruthCheck> gt;
  if (P_target && P_source) gt = checkAgainstGroundTruth(r, *P_target, *P_source, o.params.grid);
  printResult(std::cout, r, gt, o.method != "tomomap");

  if (!o.json.empty()) {
    std::ofstream out(o.json);
    auto j = toJson(r, gt);
    j["method"] = o.method;
    out << j.dump(2) << "\n";
    if (!out) throw InputError(o.json + ": cannot write JSON result");
  }
  return r.reliable ? kExitOk : kExitNoMatch;
}

}  // namespace

Command addMatchCommand(CLI::App& app) {
  auto o = std::make_shared<MatchOptions>();
  CLI::App* sub = app.add_subcommand("match", "Find T_target_source between two map files (PCD, PLY, XYZ).");
  sub->add_option("TARGET", o->target, "target map (.pcd, .ply, .xyz/.txt)")->required();
  sub->add_option("SOURCE", o->source, "source map, to be moved into the target frame")->required();
  sub->add_option("-g,--grid", o->params.grid, "grid size g [m]: voxel, pixel and slice size")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  sub->add_option("--json", o->json, "also write the result as JSON to FILE");
  sub->add_option("-m,--method", o->method, "tomomap, or the fpfh-ransac baseline (PCL) for comparison")
      ->capture_default_str()
      ->check(CLI::IsMember({"tomomap", "fpfh-ransac"}));
  sub->add_option("--gt-target", o->gt_target, "target's ground-truth pose file (3x4 row-major)");
  sub->add_option("--gt-source", o->gt_source, "source's ground-truth pose file (3x4 row-major)");
  sub->add_option("--features", o->params.features.max_features, "ORB keypoints kept per slice")
      ->capture_default_str()
      ->check(CLI::Range(10, 100000));
  sub->add_option("-j,--threads", o->params.threads, "worker threads (0 = all cores)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  sub->add_flag("--progress", o->progress, "show progress even when stderr is not a terminal");
  sub->add_flag("-q,--quiet", o->quiet, "print only the result");
  sub->footer("Exit codes: 0 reliable match, 1 no reliable match, 2 bad input, 3 internal error.");
  return {sub, [o] {
            if ((o->gt_target.empty()) != (o->gt_source.empty()))
              throw InputError("--gt-target and --gt-source go together");
            return runMatch(*o);
          }};
}

}  // namespace tomomap::cli
