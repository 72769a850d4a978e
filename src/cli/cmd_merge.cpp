// `tomomap merge MAP... -o DIR`: the fleet's map from robots' maps, placed by
// a daemon's frame.json or by matching them here.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <tuple>

#include "commands.hpp"
#include "core/fleet_map.hpp"
#include "core/gravity.hpp"
#include "core/text.hpp"
#include "core/voxel_filter.hpp"
#include "grid_option.hpp"
#include "io/map_io.hpp"
#include "results/fleet_frame.hpp"
#include "viz/fleet_map_files.hpp"

namespace tomomap::cli {
namespace {

namespace fs = std::filesystem;

struct MergeOptions {
  std::vector<std::string> maps;  // "agent=path" or "path"
  std::string out = "fleet-map";
  std::string frame;  // a daemon's frame.json; empty: match here
  MatchParams params;
  std::vector<double> band{HeightBand{}.low, HeightBand{}.high};
};

struct NamedMap {
  std::string agent, path;
};

/// "alpha=maps/a.pcd" names its robot; a bare path is named after its file.
std::vector<NamedMap> namedMaps(const std::vector<std::string>& args) {
  std::vector<NamedMap> maps;
  for (const auto& a : args) {
    const size_t eq = a.find('=');
    NamedMap m = eq == std::string::npos ? NamedMap{fs::path(a).stem().string(), a}
                                         : NamedMap{a.substr(0, eq), a.substr(eq + 1)};
    if (m.agent.empty() || m.path.empty()) throw InputError("'" + a + "': give a map as PATH or AGENT=PATH");
    for (const auto& other : maps)
      if (other.agent == m.agent)
        throw InputError("two maps are named " + m.agent + ": name them (AGENT=PATH) to tell them apart");
    maps.push_back(std::move(m));
  }
  return maps;
}

/// The frame's poses in the reference's map levelled (z up, so that the 2D
/// grid's heights mean something even where the reference's map leans):
/// p_reference_levelled = T * p_agent.
std::map<std::string, Eigen::Matrix4d> levelPoses(const FleetFrame& frame) {
  std::map<std::string, Eigen::Matrix4d> poses;
  const AgentPose* reference = frame.pose(frame.reference);
  if (!reference) return poses;
  for (const auto& p : frame.poses) poses[p.agent] = levelingMatrix(reference->up) * frame.ownFramePose(p);
  return poses;
}

/// The same from a daemon's frame.json, and its reference.
std::pair<std::string, std::map<std::string, Eigen::Matrix4d>> readFrameFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open");
  try {
    const auto j = nlohmann::json::parse(in);
    const std::string reference = j.at("reference").get<std::string>();
    std::map<std::string, Eigen::Matrix4d> poses;
    Eigen::Vector3d reference_up = Eigen::Vector3d::UnitZ();
    for (const auto& a : j.at("agents")) {
      const std::string agent = a.at("agent").get<std::string>();
      // Files of daemons from before maps were levelled hold the 4-DoF pose alone, and no up.
      poses[agent] = a.contains("T_reference_agent_6dof") ? matrixFromJson(a.at("T_reference_agent_6dof"))
                                                          : matrixFromJson(a.at("T_reference_agent").at("matrix"));
      if (agent == reference && a.contains("up")) reference_up = upFromJson(a.at("up"), reference + "'s up");
    }
    for (auto& [agent, T] : poses) T = levelingMatrix(reference_up) * T;
    return {reference, poses};
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path + ": not a frame.json: " + e.what());
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
}

/// Matches every pair of maps and solves the fleet's frame, as the daemons do.
FleetFrame matchAll(const std::vector<NamedMap>& maps, const std::vector<MapFeatures>& features,
                    const MatchParams& params) {
  std::vector<AgreedTransform> agreed;
  std::vector<std::string> agents;
  for (const auto& m : maps) agents.push_back(m.agent);
  for (size_t i = 0; i < maps.size(); ++i)
    for (size_t j = i + 1; j < maps.size(); ++j) {
      // A pair's target is the lower id, as in the fleet (AgreedTransform).
      const size_t t = maps[i].agent < maps[j].agent ? i : j, s = t == i ? j : i;
      AgreedTransform a = agreedOf(matchFeatures(features[t], features[s], params), features[t], features[s]);
      a.target = maps[t].agent;
      a.source = maps[s].agent;
      const Pose4& T = a.T_target_source;
      std::cout << "pair             " << pairText(a.pair()) << ": "
                << (a.reliable ? "x " + fixed(T.x, 3) + " y " + fixed(T.y, 3) + " z " + fixed(T.z, 3) + " m, yaw " +
                                     fixed(degrees(T.yaw), 2) + " deg, " + a.answered_by + " " +
                                     fixed(a.lead_sigma, 1) + " sigma clear"
                               : "no reliable match: " + a.reason)
                << "\n";
      agreed.push_back(std::move(a));
    }
  const CycleLimits limits{params.consensus_translation_cells * params.grid, params.consensus_yaw};
  FleetFrame frame = buildFleetFrame(agreed, agents, maps.front().agent, limits);
  for (const auto& v : frame.pairs)
    if (v.verdict == Consistency::Inconsistent)
      std::cerr << "warning: " << pairText(v.pair) << " contradicts the other pairs (the loop "
                << chainText(v.cycle, true) << " misses by " << fixed(v.cycle_translation, 2)
                << " m): left out of the frame\n";
  return frame;
}

int runMerge(const MergeOptions& o) {
  const std::vector<NamedMap> maps = namedMaps(o.maps);
  if (o.band.size() != 2 || !HeightBand{o.band[0], o.band[1]}.valid())
    throw InputError("--band must be LOW,HIGH with LOW < HIGH");
  std::error_code ec;  // checked before the work, so a typo costs no time
  fs::create_directories(o.out, ec);
  if (ec || !fs::is_directory(o.out)) throw InputError(o.out + ": cannot create the output folder: " + ec.message());

  std::string reference;
  std::map<std::string, Eigen::Matrix4d> poses;
  if (!o.frame.empty()) std::tie(reference, poses) = readFrameFile(o.frame);

  // Each map once: its cells at the grid (what a daemon holds of a peer's
  // map), and, to match here, its description.
  std::vector<Points> cells;
  std::vector<MapFeatures> features;
  for (const auto& m : maps) {
    size_t nonfinite = 0;
    const Points points = loadMap(m.path, &nonfinite);
    std::cout << "map              " << m.agent << ": " << m.path << " (" << points.size() << " points"
              << (nonfinite ? ", " + std::to_string(nonfinite) + " non-finite dropped" : "") << ")\n";
    cells.push_back(voxelFilter(points, o.params.grid));
    if (o.frame.empty()) features.push_back(describeMap(points, o.params));
  }
  if (o.frame.empty()) {
    if (maps.size() < 2) throw InputError("give two maps or more to match, or a frame.json (--frame) to place one");
    const FleetFrame frame = matchAll(maps, features, o.params);
    reference = frame.reference;
    poses = levelPoses(frame);
  }

  std::vector<PlacedMap> placed;
  std::vector<std::string> left_out;
  for (size_t i = 0; i < maps.size(); ++i) {
    const auto pose = poses.find(maps[i].agent);
    if (pose == poses.end()) {
      left_out.push_back(maps[i].agent);
      continue;
    }
    placed.push_back({maps[i].agent, std::move(cells[i]), pose->second});
  }
  // The reference's map first: where maps overlap, its cells keep its colour.
  std::stable_partition(placed.begin(), placed.end(), [&](const PlacedMap& m) { return m.agent == reference; });
  for (const auto& agent : left_out)
    std::cerr << "warning: " << agent << "'s map is not placed in " << reference
              << "'s frame (no reliable path of pairs to it): left out\n";
  if (placed.empty()) throw InputError("none of the maps is placed in " + reference + "'s frame");

  const FleetMap merged = mergeMaps(placed, o.params.grid);
  const HeightBand band{o.band[0], o.band[1]};
  const FleetGrid fleet_grid = fleetGrid(merged, band);
  const OccupancyGrid2D& grid = fleet_grid.grid;
  const double floor = fleet_grid.floor;
  const std::string stem = viz::writeFleetMapFiles(
      o.out, merged, fleet_grid, viz::fleetMapCaption(merged, fleet_grid, band, reference + "'s frame, levelled"));
  std::string counts;
  for (size_t r = 0; r < merged.agents.size(); ++r)
    counts += (r ? ", " : "") + merged.agents[r] + " " + std::to_string(merged.cells_of[r]);
  std::cout << "fleet map        " << stem << ".pcd: " << merged.points.size() << " cells at g " << o.params.grid
            << " m in " << reference << "'s frame, levelled (cells per robot: " << counts
            << "; fields x y z rgba label, label = the robot's place in this list)\n"
            << "2D grid          " << stem << ".pgm, " << stem << ".yaml: " << grid.width << " x " << grid.height
            << " cells, occupied where a map holds something " << fixed(o.band[0], 2) << "-" << fixed(o.band[1], 2)
            << " m above the floor (z " << fixed(floor, 2) << " m), unknown elsewhere\n"
            << "picture          " << stem << ".png\n";
  return left_out.empty() ? 0 : 1;
}

}  // namespace

Command addMergeCommand(CLI::App& app) {
  auto o = std::make_shared<MergeOptions>();
  CLI::App* sub = app.add_subcommand(
      "merge",
      "Merge robots' maps into the fleet's map: a PCD coloured by robot, a 2D occupancy grid (map_server's PGM + "
      "YAML) and a picture. Placed by a daemon's frame.json, or matched here.");
  sub->add_option("MAP", o->maps,
                  "maps as PATH or AGENT=PATH (the agent ids frame.json names); the first is the "
                  "reference when matching here")
      ->required();
  sub->add_option("-o,--out", o->out, "output folder: fleet_map.pcd, .pgm, .yaml, .png")->capture_default_str();
  sub->add_option("--frame", o->frame, "a daemon's frame.json: place the maps by it instead of matching them")
      ->check(CLI::ExistingFile);
  sub->add_option("-g,--grid", o->params.grid, "grid size g [m]: the merged map's cells and the matching's")
      ->capture_default_str()
      ->check(gridSize());
  sub->add_option("--band", o->band,
                  "LOW,HIGH: heights above the floor [m] whose cells are the 2D grid's obstacles (the robot's body)")
      ->expected(2)
      ->delimiter(',')
      ->capture_default_str();
  sub->add_option("-j,--threads", o->params.threads, "worker threads (0 = all cores)")
      ->capture_default_str()
      ->check(settingRange("threads"));
  sub->footer("Exit codes: 0 every map placed, 1 some map left out (no reliable path to the reference), 2 bad input.");
  return {sub, [o] { return runMerge(*o); }};
}

}  // namespace tomomap::cli
