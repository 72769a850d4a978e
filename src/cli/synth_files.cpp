#include "synth_files.hpp"

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "io/map_io.hpp"

namespace tomomap::cli {

namespace {

void makeFolder(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir + ": cannot create output directory: " + ec.message());
}

/// map_N.pcd and map_N-gtpose.txt of each map into `dir`.
GeneratedWorld writeMaps(const std::vector<const synth::SynthMap*>& maps, const std::string& dir) {
  GeneratedWorld out;
  for (size_t i = 0; i < maps.size(); ++i) {
    const std::string stem = (std::filesystem::path(dir) / ("map_" + std::to_string(i))).string();
    savePcd(stem + ".pcd", maps[i]->points);
    savePoseFile(stem + "-gtpose.txt", maps[i]->pose);
    out.maps.push_back(stem + ".pcd");
    out.poses.push_back(stem + "-gtpose.txt");
    out.points.push_back(maps[i]->points.size());
  }
  return out;
}

}  // namespace

GeneratedWorld writeSynthWorld(const synth::SceneParams& params, const synth::NoiseModel& noise, const std::string& dir,
                               const std::function<void(size_t, size_t)>& progress) {
  makeFolder(dir);
  const synth::Scene scene = synth::makeScene(params);
  auto maps = synth::scanScene(scene, noise, params.seed, progress);
  for (size_t i = 1; i < maps.size() && params.tilt != 0.0; ++i) synth::roll(maps[i], params.tilt);

  std::vector<const synth::SynthMap*> written;
  for (const auto& m : maps) written.push_back(&m);
  GeneratedWorld out = writeMaps(written, dir);
  out.grid = scene.grid;
  nlohmann::json index = {
      {"world", synth::toString(params.type)},
      {"seed", params.seed},
      {"grid", scene.grid},
      {"tilt_deg", degrees(params.tilt)},
      {"noise", {{"pose_translation", noise.pose_translation}, {"pose_yaw", noise.pose_yaw}, {"range", noise.range}}},
      {"maps", nlohmann::json::array()}};
  for (size_t i = 0; i < maps.size(); ++i) {
    index["maps"].push_back({{"map", out.maps[i]},
                             {"pose", out.poses[i]},
                             {"points", maps[i].points.size()},
                             {"scans", scene.trajectories[i].size()},
                             {"rays", maps[i].rays},
                             {"hits", maps[i].hits}});
  }
  std::ofstream(std::filesystem::path(dir) / "scene.json") << index.dump(2) << "\n";
  return out;
}

GeneratedWorld writeScanPair(const std::string& scan_file, const synth::ScanPairParams& params, const std::string& dir,
                             std::string* name) {
  makeFolder(dir);
  size_t nonfinite = 0;
  const synth::ScanPair pair = synth::makeScanPair(loadMap(scan_file, &nonfinite), params);
  GeneratedWorld out = writeMaps({&pair.target, &pair.source}, dir);
  const auto& i = pair.info;
  std::ofstream(std::filesystem::path(dir) / "pair.json")
      << nlohmann::json{{"scan", scan_file},
                        {"seed", params.seed},
                        {"nonfinite_dropped", nonfinite},
                        {"overlap", i.overlap},
                        {"cut_yaw_deg", degrees(i.cut_yaw)},
                        {"degraded", i.target_degraded ? "target" : "source"},
                        {"thinning", i.thinning},
                        {"noise_m", i.noise},
                        {"move", {{"x", i.move.x}, {"y", i.move.y}, {"z", i.move.z}, {"yaw_deg", degrees(i.move.yaw)}}},
                        {"points", out.points}}
             .dump(2)
      << "\n";
  if (name) *name = synth::describe(i);
  return out;
}

GeneratedWorld writeSequencePair(const std::vector<PosedScan>& scans, const Eigen::Vector3d& up,
                                 const synth::SequencePairParams& params, const std::string& dir, std::string* name) {
  makeFolder(dir);
  const synth::SequencePair pair = synth::makeSequencePair(scans, up, params);
  GeneratedWorld out = writeMaps({&pair.target, &pair.source}, dir);
  const auto& i = pair.info;
  std::ofstream(std::filesystem::path(dir) / "pair.json")
      << nlohmann::json{{"seed", params.seed},
                        {"keyframes",
                         {{"target", {i.target_first, i.target_last}}, {"source", {i.source_first, i.source_last}}}},
                        {"overlap", {{"target", i.target_overlap}, {"source", i.source_overlap}}},
                        {"lean_deg", {{"target", degrees(i.target_lean)}, {"source", degrees(i.source_lean)}}},
                        {"levelled", i.level},
                        {"turned_deg", i.turn_deg},
                        {"range_m", {params.min_range, params.max_range}},
                        {"voxel_m", params.voxel},
                        {"move", {{"x", i.move.x}, {"y", i.move.y}, {"z", i.move.z}, {"yaw_deg", degrees(i.move.yaw)}}},
                        {"points", out.points}}
             .dump(2)
      << "\n";
  if (name) *name = synth::describe(i);
  return out;
}

}  // namespace tomomap::cli
