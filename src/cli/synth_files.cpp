#include "synth_files.hpp"

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "io/map_io.hpp"

namespace tomomap::cli {

GeneratedWorld writeSynthWorld(const synth::SceneParams& params, const synth::NoiseModel& noise, const std::string& dir,
                               const std::function<void(size_t, size_t)>& progress) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir + ": cannot create output directory: " + ec.message());
  const synth::Scene scene = synth::makeScene(params);
  auto maps = synth::scanScene(scene, noise, params.seed, progress);
  for (size_t i = 1; i < maps.size() && params.tilt != 0.0; ++i) synth::roll(maps[i], params.tilt);

  GeneratedWorld out;
  out.grid = scene.grid;
  nlohmann::json index = {
      {"world", synth::toString(params.type)},
      {"seed", params.seed},
      {"grid", scene.grid},
      {"tilt_deg", degrees(params.tilt)},
      {"noise", {{"pose_translation", noise.pose_translation}, {"pose_yaw", noise.pose_yaw}, {"range", noise.range}}},
      {"maps", nlohmann::json::array()}};
  for (size_t i = 0; i < maps.size(); ++i) {
    const std::string stem = (std::filesystem::path(dir) / ("map_" + std::to_string(i))).string();
    savePcd(stem + ".pcd", maps[i].points);
    savePoseFile(stem + "-gtpose.txt", maps[i].pose);
    out.maps.push_back(stem + ".pcd");
    out.poses.push_back(stem + "-gtpose.txt");
    out.points.push_back(maps[i].points.size());
    index["maps"].push_back({{"map", stem + ".pcd"},
                             {"pose", stem + "-gtpose.txt"},
                             {"points", maps[i].points.size()},
                             {"scans", scene.trajectories[i].size()},
                             {"rays", maps[i].rays},
                             {"hits", maps[i].hits}});
  }
  std::ofstream(std::filesystem::path(dir) / "scene.json") << index.dump(2) << "\n";
  return out;
}

}  // namespace tomomap::cli
