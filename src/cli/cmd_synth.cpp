// `tomomap synth`: generate overlapping maps of a procedural world with ground truth.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "core/map_io.hpp"
#include "exit_codes.hpp"
#include "progress.hpp"
#include "synth/synth.hpp"

namespace tomomap::cli {
namespace {

struct SynthOptions {
  std::string world = "indoor", noise = "low", out;
  uint64_t seed = 1;
  int maps = 2;
  double scale = 1.0;
  std::optional<double> pose_sigma, yaw_sigma, range_sigma;
  bool progress = false;
};

int runSynth(const SynthOptions& o) {
  synth::SceneParams sp;
  sp.type = synth::parseWorldType(o.world);
  sp.seed = o.seed;
  sp.maps = o.maps;
  sp.scale = o.scale;
  synth::NoiseModel noise = synth::noiseLevel(o.noise);
  if (o.pose_sigma) noise.pose_translation = *o.pose_sigma;
  if (o.yaw_sigma) noise.pose_yaw = *o.yaw_sigma;
  if (o.range_sigma) noise.range = *o.range_sigma;

  std::error_code ec;
  std::filesystem::create_directories(o.out, ec);
  if (ec) throw InputError(o.out + ": cannot create output directory: " + ec.message());

  const synth::Scene scene = synth::makeScene(sp);
  const bool show = o.progress || stderrIsTerminal();
  const auto maps = synth::scanScene(scene, noise, o.seed, [show](size_t done, size_t total) {
    if (show && (done % 16 == 0 || done == total)) terminalProgress(true)("scans", done, total);
  });

  nlohmann::json index = {
      {"world", o.world},
      {"seed", o.seed},
      {"grid", scene.grid},
      {"noise", {{"pose_translation", noise.pose_translation}, {"pose_yaw", noise.pose_yaw}, {"range", noise.range}}},
      {"maps", nlohmann::json::array()}};
  for (size_t i = 0; i < maps.size(); ++i) {
    const std::string stem = (std::filesystem::path(o.out) / ("map_" + std::to_string(i))).string();
    savePcd(stem + ".pcd", maps[i].points);
    savePoseFile(stem + "-gtpose.txt", maps[i].pose);
    index["maps"].push_back({{"map", stem + ".pcd"},
                             {"pose", stem + "-gtpose.txt"},
                             {"points", maps[i].points.size()},
                             {"scans", scene.trajectories[i].size()}});
    std::cout << stem << ".pcd  " << maps[i].points.size() << " points from " << scene.trajectories[i].size()
              << " scans (" << maps[i].hits << " of " << maps[i].rays << " rays hit)\n";
  }
  std::ofstream(std::filesystem::path(o.out) / "scene.json") << index.dump(2) << "\n";
  std::cout << "match with: tomomap match " << o.out << "/map_0.pcd " << o.out << "/map_1.pcd --grid " << scene.grid
            << " --gt-target " << o.out << "/map_0-gtpose.txt --gt-source " << o.out << "/map_1-gtpose.txt\n";
  return kExitOk;
}

}  // namespace

Command addSynthCommand(CLI::App& app) {
  auto o = std::make_shared<SynthOptions>();
  CLI::App* sub =
      app.add_subcommand("synth", "Generate overlapping maps of a procedural world with ground-truth poses.");
  sub->add_option("-o,--out", o->out, "output directory (map_N.pcd, map_N-gtpose.txt, scene.json)")->required();
  sub->add_option("-w,--world", o->world, "world type: indoor (2-floor building) or outdoor (street)")
      ->capture_default_str()
      ->check(CLI::IsMember({"indoor", "outdoor"}));
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
  sub->add_flag("--progress", o->progress, "show progress even when stderr is not a terminal");
  return {sub, [o] { return runSynth(*o); }};
}

}  // namespace tomomap::cli
