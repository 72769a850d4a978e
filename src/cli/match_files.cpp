#include "match_files.hpp"

#include <CLI/CLI.hpp>
#include <chrono>
#include <exception>
#include <future>
#include <iostream>
#include <optional>

#include "core/map_bounds.hpp"
#include "core/text.hpp"
#include "grid_option.hpp"
#include "io/map_io.hpp"
#include "progress.hpp"

namespace tomomap::cli {

namespace {

/// One map read and described, and what is to be said of it: said once both
/// maps are done, in order, whichever finished first.
struct Described {
  MapFeatures features;
  StageTimings spent;
  nlohmann::json inputs;
  std::string out, err;  ///< for stdout and stderr
};

/// x, y, z from an --up option, if given.
std::optional<Eigen::Vector3d> upOf(const std::vector<double>& v) {
  if (v.empty()) return std::nullopt;
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

Described describeFile(const std::string& path, const std::string& role, const MatchParams& params, bool quiet,
                       const std::vector<double>& up, Points* sample = nullptr) {
  Described d;
  size_t nonfinite = 0;
  std::string note;
  const auto t0 = std::chrono::steady_clock::now();
  const Points map = loadMap(path, &nonfinite, &note);  // dropped once described
  d.spent.load = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!note.empty()) d.err += "note: " + note + "\n";
  d.inputs[role] = path;
  d.inputs[role + "_points"] = map.size();
  d.inputs[role + "_nonfinite_dropped"] = nonfinite;
  if (nonfinite > 0)
    d.err +=
        "warning: " + path + ": dropped " + std::to_string(nonfinite) + " points with NaN or infinite coordinates\n";
  if (!quiet) d.out += role + " " + path + " (" + std::to_string(map.size()) + " points)\n";
  if (sample) *sample = sourceSample(map);
  d.features = describeMap(map, params, &d.spent, nullptr, nullptr, upOf(up));
  const MapFeatures& f = d.features;
  if (f.leveled) d.err += "note: " + path + ": levelled: it leaned " + leanText(f.tilt) + "\n";
  d.inputs[role + "_stray_voxels"] = f.occupancy.stray;
  if (f.occupancy.stray > 0)
    d.err += "warning: " + path + ": left out " + std::to_string(f.occupancy.stray) +
             " stray voxels far from the rest of the map (a gap of " + fixed(kStrayGap, 0) + " m or more)\n";
  return d;
}

}  // namespace

MatchedFiles matchFiles(MatchFilesOptions o) {
  if (o.json == "-") o.quiet = true;  // stdout is the JSON's alone
  if (!(o.params.grid > 0.0)) throw InputError("grid size must be positive");
  MatchParams params = o.params;
  params.max_tilt = radians(o.max_tilt_deg);
  requireBothOrNeither(o.gt_target, o.gt_source);
  MatchedFiles m;
  for (const auto& [name, up] : {std::pair{"--up-target", &o.up_target}, std::pair{"--up-source", &o.up_source}})
    if (const auto v = upOf(*up); v && !(v->allFinite() && v->norm() > 0))
      throw InputError(std::string(name) + " must be a non-zero direction X,Y,Z");
  if (!o.gt_target.empty()) m.truth = GroundTruth{loadPoseFile(o.gt_target), loadPoseFile(o.gt_source), {}};
  Points* sample = m.truth ? &m.truth->source_sample : nullptr;

  // With two threads or more both maps are read and described at once, each
  // on one thread: the building (1.85 M points a map) at g 0.2 in 0.12 s
  // instead of 0.16, holding both raw maps at once (100 MB instead of 61).
  // With one they are read in turn, each dropped once described.
  const bool together = matchThreads(params) >= 2;
  MatchParams each = params;
  if (together) each.threads = 1;
  auto target_job = std::async(together ? std::launch::async : std::launch::deferred,
                               [&] { return describeFile(o.target, "target", each, o.quiet, o.up_target); });
  std::optional<Described> source;
  std::exception_ptr source_failed;
  if (together) try {
      source = describeFile(o.source, "source", each, o.quiet, o.up_source, sample);
    } catch (...) {
      source_failed = std::current_exception();
    }
  StageTimings timings;
  auto say = [&](const Described& d) {
    std::cerr << d.err;
    std::cout << d.out;
    m.inputs.update(d.inputs);
    // A stage's time is wall time: for maps described at once, the longer one's.
    for (auto [mine, theirs] : {std::pair{&timings.load, d.spent.load},
                                {&timings.voxel, d.spent.voxel},
                                {&timings.slicing, d.spent.slicing},
                                {&timings.features, d.spent.features}})
      *mine = together ? std::max(*mine, theirs) : *mine + theirs;
  };
  Described target = target_job.get();  // a bad target is reported first, as when read in turn
  say(target);
  m.target = std::move(target.features);
  if (source_failed) std::rethrow_exception(source_failed);
  if (!source) source = describeFile(o.source, "source", each, o.quiet, o.up_source, sample);
  say(*source);
  m.source = std::move(source->features);
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
  sub.add_flag("--finish,!--no-finish", o.params.finish,
               "refine a reliable answer in all six degrees of freedom on the maps' occupancy (on by default)");
  for (auto [name, v] : {std::pair{"--up-target", &o.up_target}, std::pair{"--up-source", &o.up_source}})
    sub.add_option(name, *v,
                   std::string("the ") + (v == &o.up_target ? "target" : "source") +
                       " map's up direction X Y Z in its own frame, where it is known (an IMU's or the SLAM's "
                       "gravity estimate): not estimated then, and the map levelled by it")
        ->expected(3)
        ->delimiter(',');
  sub.add_flag("--candidates", o.candidates,
               "list every pose the searches proposed, refined and scored on the occupancy, with its error "
               "where ground truth is given");
  sub.add_flag("--exhaustive", o.params.exhaustive,
               "match every slice pair instead of the height offsets the descriptor index points to "
               "(same answers, n^2 cost; for checking)");
  sub.add_flag("--progress", o.progress, "show progress even when stderr is not a terminal");
  sub.add_flag("-q,--quiet", o.quiet, "print only the result, one line");
}

}  // namespace tomomap::cli
