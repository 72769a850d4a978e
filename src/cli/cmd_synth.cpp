// `tomomap synth`: generate overlapping maps of a procedural world with ground truth.
#include <iostream>

#include "commands.hpp"
#include "exit_codes.hpp"
#include "progress.hpp"
#include "synth_files.hpp"

namespace tomomap::cli {
namespace {

struct SynthOptions {
  std::string world = "indoor", noise = "low", out;
  uint64_t seed = 1;
  int maps = 2;
  double scale = 1.0, tilt_deg = 0.0;
  std::optional<double> pose_sigma, yaw_sigma, range_sigma;
  bool progress = false;
};

int runSynth(const SynthOptions& o) {
  synth::SceneParams sp;
  sp.type = synth::parseWorldType(o.world);
  sp.seed = o.seed;
  sp.maps = o.maps;
  sp.scale = o.scale;
  sp.tilt = radians(o.tilt_deg);
  synth::NoiseModel noise = synth::noiseLevel(o.noise);
  if (o.pose_sigma) noise.pose_translation = *o.pose_sigma;
  if (o.yaw_sigma) noise.pose_yaw = *o.yaw_sigma;
  if (o.range_sigma) noise.range = *o.range_sigma;

  const Progress bar = terminalProgress(o.progress || stderrIsTerminal());
  const GeneratedWorld w = writeSynthWorld(sp, noise, o.out, [&bar](size_t done, size_t total) {
    if (bar && (done % 16 == 0 || done == total)) bar("scans", done, total);
  });
  for (size_t i = 0; i < w.maps.size(); ++i) std::cout << w.maps[i] << "  " << w.points[i] << " points\n";
  std::cout << "match with: tomomap match " << w.maps[0] << " " << w.maps.back() << " --grid " << w.grid
            << " --gt-target " << w.poses[0] << " --gt-source " << w.poses.back() << "\n";
  return kExitOk;
}

}  // namespace

Command addSynthCommand(CLI::App& app) {
  auto o = std::make_shared<SynthOptions>();
  CLI::App* sub =
      app.add_subcommand("synth", "Generate overlapping maps of a procedural world with ground-truth poses.");
  sub->add_option("-o,--out", o->out, "output directory (map_N.pcd, map_N-gtpose.txt, scene.json)")->required();
  sub->add_option(
         "-w,--world", o->world,
         "world type: indoor (2-floor building), outdoor (street) or room (one room, both sides of a partition)")
      ->capture_default_str()
      ->check(CLI::IsMember({"indoor", "outdoor", "room"}));
  sub->add_option("-s,--seed", o->seed, "random seed: same seed, same maps")->capture_default_str();
  sub->add_option("-n,--maps", o->maps, "number of maps (overlapping trajectories)")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  sub->add_option("--noise", o->noise, "noise level: none, low (0.02 m / 0.01 rad) or high (0.05 m / 0.025 rad)")
      ->capture_default_str()
      ->check(CLI::IsMember({"none", "low", "high"}));
  sub->add_option("--pose-sigma", o->pose_sigma, "override: per-scan position noise [m]")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--yaw-sigma", o->yaw_sigma, "override: per-scan yaw noise [rad]")->check(CLI::NonNegativeNumber);
  sub->add_option("--range-sigma", o->range_sigma, "override: range noise at up to 3 m [m]")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--scale", o->scale, "stretch the world's length (0.5 to 20)")
      ->capture_default_str()
      ->check(CLI::Range(0.5, 20.0));
  sub->add_option("--tilt", o->tilt_deg, "roll every map but the first this much about x [deg]: a leaning map frame")
      ->capture_default_str()
      ->check(CLI::Range(-90.0, 90.0));
  sub->add_flag("--progress", o->progress, "show progress even when stderr is not a terminal");
  return {sub, [o] { return runSynth(*o); }};
}

}  // namespace tomomap::cli
