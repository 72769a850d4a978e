// `tomomap-baseline`: the methods tomomap is measured against, on the same
// inputs and with the same output as `tomomap match`: FPFH + RANSAC, and the
// paper's plain tomographic method. A separate binary so that PCL's
// registration stack neither slows down nor inflates the memory of `tomomap`
// itself, and so that evaluations measure each method's memory on its own.
#include "baseline/fpfh_ransac.hpp"
#include "baseline/paper_consensus.hpp"
#include "grid_option.hpp"
#include "io/map_io.hpp"
#include "report.hpp"
#include "run_guarded.hpp"
#include "version.hpp"

using namespace tomomap;
using namespace tomomap::cli;

int main(int argc, char** argv) {
  CLI::App app{"tomomap-baseline " TOMOMAP_VERSION
               ": the methods tomomap is measured against.\n"
               "  fpfh-ransac: FPFH features on keypoints + RANSAC (PCL), radii scaled from the grid size.\n"
               "  paper-consensus: the paper's tomographic method as published, without tomomap's decision:\n"
               "    the height offset with the most agreeing slice pairs, whatever their number.\n"
               "Exit codes: 0 converged, 1 no reliable match, 2 bad input, 3 internal error.",
               "tomomap-baseline"};
  app.set_version_flag("-V,--version", "tomomap-baseline " TOMOMAP_VERSION);
  std::string target, source, json, gt_target, gt_source, method = "fpfh-ransac";
  baseline::FpfhParams p;
  app.add_option("-m,--method", method, "the method")
      ->capture_default_str()
      ->check(CLI::IsMember({"fpfh-ransac", "paper-consensus"}));
  app.add_option("TARGET", target, "target map (.pcd, .ply, .xyz/.txt/.csv, OctoMap .bt/.ot)")->required();
  app.add_option("SOURCE", source, "source map")->required();
  app.add_option("-g,--grid", p.grid, "grid size g [m]; radii scale with it")->capture_default_str()->check(gridSize());
  app.add_option("--keypoint-cells", p.keypoint_cells, "keypoint spacing [g]: fewer keypoints run faster")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 100.0));
  app.add_option("--iterations", p.max_iterations, "RANSAC iterations at most")
      ->capture_default_str()
      ->check(CLI::Range(100, 10000000));
  app.add_option("--json", json, "also write the result as JSON to FILE");
  app.add_option("--gt-target", gt_target, "target's ground-truth pose file (3x4 row-major)");
  app.add_option("--gt-source", gt_source, "source's ground-truth pose file (3x4 row-major)");
  app.add_option("-j,--threads", p.threads, "worker threads (0 = all cores)")
      ->capture_default_str()
      ->check(settingRange("threads"));
  return parseAndRun(app, argc, argv, [&] {
    requireBothOrNeither(gt_target, gt_source);
    std::optional<GroundTruth> truth;
    if (!gt_target.empty()) truth = GroundTruth{loadPoseFile(gt_target), loadPoseFile(gt_source), {}};
    const Points t = loadMap(target), s = loadMap(source);
    if (truth) truth->source_sample = sourceSample(s);
    const nlohmann::json sizes = {
        {"target", target}, {"source", source}, {"target_points", t.size()}, {"source_points", s.size()}};
    if (method == "paper-consensus") {
      MatchParams params;
      params.grid = p.grid;
      params.threads = p.threads;
      return report(baseline::matchPaperConsensus(t, s, params), truth, p.grid, {json, method, false}, sizes);
    }
    const baseline::FpfhResult b = baseline::matchFpfhRansac(t, s, p);
    MatchResult r;
    r.reliable = b.converged;
    if (!b.converged) r.reason = "FPFH-RANSAC did not converge";
    r.T_target_source = b.T_target_source;
    r.features.inliers = static_cast<size_t>(b.inlier_fraction * static_cast<double>(b.source_keypoints));
    r.target_features = b.target_keypoints;
    r.source_features = b.source_keypoints;
    r.timings.features = b.describe_seconds;
    r.timings.pair_matching = b.ransac_seconds;
    return report(r, truth, p.grid, {json, method, false}, sizes);
  });
}
