// `tomomap match TARGET SOURCE`: offline registration of two map files.
#include <fstream>
#include <iostream>

#include "commands.hpp"
#include "core/map_io.hpp"
#include "exit_codes.hpp"
#include "progress.hpp"
#include "report.hpp"

namespace tomomap::cli {
namespace {

struct MatchOptions {
  std::string target, source, json, gt_target, gt_source;
  MatchParams params;
  bool progress = false, quiet = false;
};

int runMatch(const MatchOptions& o) {
  if (!(o.params.grid > 0.0)) throw InputError("grid size must be positive");
  std::optional<Eigen::Matrix4d> P_target, P_source;
  if (!o.gt_target.empty()) P_target = loadPoseFile(o.gt_target);
  if (!o.gt_source.empty()) P_source = loadPoseFile(o.gt_source);

  // One map at a time: its raw points are dropped once described, which halves
  // peak memory on maps of millions of points.
  StageTimings timings;
  nlohmann::json sizes;
  auto describe = [&](const std::string& path, const char* role) {
    const Points map = loadMap(path);
    sizes[std::string(role) + "_points"] = map.size();
    if (!o.quiet) std::cout << role << " " << path << " (" << map.size() << " points)\n";
    return describeMap(map, o.params, &timings);
  };
  const MapFeatures target = describe(o.target, "target");
  const MapFeatures source = describe(o.source, "source");
  if (!o.quiet) std::cout << "grid " << o.params.grid << " m\n";
  MatchResult r = matchFeatures(target, source, o.params, terminalProgress(o.progress || stderrIsTerminal()));
  r.timings.takeDescription(timings);
  return report(r, P_target, P_source, o.params.grid, o.json, false, sizes);
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
            requireBothOrNeither(o->gt_target, o->gt_source);
            return runMatch(*o);
          }};
}

}  // namespace tomomap::cli
