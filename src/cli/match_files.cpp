#include "match_files.hpp"

#include <CLI/CLI.hpp>
#include <chrono>
#include <iostream>

#include "core/map_bounds.hpp"
#include "core/text.hpp"
#include "grid_option.hpp"
#include "io/map_io.hpp"
#include "progress.hpp"

namespace tomomap::cli {

MatchedFiles matchFiles(MatchFilesOptions o) {
  if (o.json == "-") o.quiet = true;  // stdout is the JSON's alone
  if (!(o.params.grid > 0.0)) throw InputError("grid size must be positive");
  MatchParams params = o.params;
  params.max_tilt = radians(o.max_tilt_deg);
  requireBothOrNeither(o.gt_target, o.gt_source);
  MatchedFiles m;
  if (!o.gt_target.empty()) m.P_target = loadPoseFile(o.gt_target);
  if (!o.gt_source.empty()) m.P_source = loadPoseFile(o.gt_source);
  StageTimings timings;
  auto describe = [&](const std::string& path, const char* role) {
    size_t nonfinite = 0;
    std::string note;
    const auto t0 = std::chrono::steady_clock::now();
    const Points map = loadMap(path, &nonfinite, &note);
    timings.load += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!note.empty()) std::cerr << "note: " << note << "\n";
    m.inputs[role] = path;
    m.inputs[std::string(role) + "_points"] = map.size();
    m.inputs[std::string(role) + "_nonfinite_dropped"] = nonfinite;
    if (nonfinite > 0)
      std::cerr << "warning: " << path << ": dropped " << nonfinite << " points with NaN or infinite coordinates\n";
    if (!o.quiet) std::cout << role << " " << path << " (" << map.size() << " points)\n";
    MapFeatures f = describeMap(map, params, &timings);
    if (f.leveled)
      std::cerr << "note: " << path << ": levelled: it leaned " << fixed(degrees(f.tilt.angle), 1) << " +- "
                << fixed(degrees(f.tilt.uncertainty), 1) << " deg from gravity (read off its "
                << (f.tilt.cue == Tilt::Cue::floors ? "floors" : "walls") << ")\n";
    m.inputs[std::string(role) + "_stray_voxels"] = f.occupancy.stray;
    if (f.occupancy.stray > 0)
      std::cerr << "warning: " << path << ": left out " << f.occupancy.stray
                << " stray voxels far from the rest of the map (a gap of " << kStrayGap << " m or more)\n";
    return f;
  };
  m.target = describe(o.target, "target");
  m.source = describe(o.source, "source");
  if (!o.quiet) std::cout << "grid " << o.params.grid << " m\n";
  m.result = matchFeatures(m.target, m.source, params, terminalProgress(o.progress || stderrIsTerminal()));
  m.result.timings.takeDescription(timings);
  return m;
}

void addMatchOptions(CLI::App& sub, MatchFilesOptions& o) {
  sub.add_option("-g,--grid", o.params.grid, "grid size g [m]: voxel, pixel and slice size")
      ->capture_default_str()
      ->check(gridSize());
  sub.add_option("--json", o.json,
                 "also write the result as JSON to FILE (- for stdout; the text then goes to stderr)");
  sub.add_option("--gt-target", o.gt_target, "target's ground-truth pose file (3x4 row-major)");
  sub.add_option("--gt-source", o.gt_source, "source's ground-truth pose file (3x4 row-major)");
  sub.add_option("--features", o.params.features.max_features, "ORB keypoints kept per slice")
      ->capture_default_str()
      ->check(settingRange("max_features"));
  sub.add_option("-j,--threads", o.params.threads, "worker threads (0 = all cores)")
      ->capture_default_str()
      ->check(settingRange("threads"));
  sub.add_option("--max-tilt", o.max_tilt_deg, "level (or refuse) a map tilted more than this from gravity [deg]")
      ->capture_default_str()
      ->check(settingRange("max_tilt_deg"));
  sub.add_flag("--level,!--no-level", o.params.level,
               "level a map tilted beyond --max-tilt (turn its up onto z; on by default); --no-level refuses it");
  sub.add_flag("--exhaustive", o.params.exhaustive,
               "match every slice pair instead of the height offsets the descriptor index points to "
               "(same answers, n^2 cost; for checking)");
  sub.add_flag("--progress", o.progress, "show progress even when stderr is not a terminal");
  sub.add_flag("-q,--quiet", o.quiet, "print only the result, one line");
}

}  // namespace tomomap::cli
