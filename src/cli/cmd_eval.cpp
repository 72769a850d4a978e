// `tomomap eval SUITE`: every pair of a suite through every method, each run as
// its own process (so time and peak memory are that method's alone), rows
// written as they finish, and a Markdown summary at the end.
#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <tuple>

#include "child_process.hpp"
#include "commands.hpp"
#include "core/match_params.hpp"
#include "core/stats.hpp"
#include "exit_codes.hpp"
#include "grid_option.hpp"
#include "io/map_io.hpp"
#include "io/pose_sequence.hpp"
#include "results/json_schema.hpp"
#include "suite.hpp"
#include "synth_files.hpp"
#include "transport/wire_sizes.hpp"
#include "viz/box_plot.hpp"

namespace tomomap::cli {
namespace {

namespace fs = std::filesystem;

/// Bytes a slice's header adds to its features (transport::kFeatureBytes each)
/// in the payload estimate.
constexpr double kBytesPerSlice = 8;

struct Row {
  std::string pair, noise, family, method;
  int exit_code = -1;
  bool reliable = false, success = false;
  double grid = 0, translation_error = NAN, origin_error = NAN, yaw_error = NAN, seconds = 0, cpu_seconds = 0,
         peak_rss_mb = 0;
  double features = 0, slices = 0, payload_bytes = 0, raw_bytes = 0;
  std::string note;
};

const char* kCsvHeader =
    "pair,noise,family,method,exit_code,reliable,success,translation_error_m,yaw_error_rad,wall_s,cpu_s,peak_rss_mb,"
    "features,feature_payload_bytes,raw_map_bytes,note";

std::string csv(const Row& r) {
  std::ostringstream o;
  o << std::setprecision(6) << '"' << r.pair << "\"," << r.noise << ",\"" << r.family << "\"," << r.method << ','
    << r.exit_code << ',' << r.reliable << ',' << r.success << ',' << r.translation_error << ',' << r.yaw_error << ','
    << r.seconds << ',' << r.cpu_seconds << ',' << r.peak_rss_mb << ',' << r.features << ',' << r.payload_bytes << ','
    << r.raw_bytes << ",\"" << r.note << '"';
  return o.str();
}

/// 0.5 -> "0.5", 2 -> "2": for names.
std::string shortNumber(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

/// `p`'s name as a file name: anything but letters, digits, dots and dashes made '_'.
std::string fileNameOf(std::string name) {
  for (char& ch : name)
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '.' && ch != '-') ch = '_';
  return name;
}

/// One run of `method` on `p`; with `candidates`, tomomap lists its
/// candidates and the run's JSON is kept as OUT/results/PAIR.METHOD.json.
Row runOne(const SuitePair& p, const std::string& method, const fs::path& scratch, int threads, double timeout_s,
           bool candidates) {
  Row row;
  row.pair = p.name;
  row.noise = p.noise;
  row.family = p.family;
  row.method = method;
  row.grid = p.grid;
  const std::string json = (scratch / "result.json").string();
  fs::remove(json);
  std::vector<std::string> argv;
  if (method == "tomomap")
    argv = {selfBinary(), "match", "-q"};
  else
    argv = {siblingBinary("tomomap-baseline"), "--method", method};
  if (method == "tomomap" && candidates) argv.push_back("--candidates");
  for (const auto& a : {p.target, p.source, std::string("--grid"), std::to_string(p.grid), std::string("--json"), json,
                        std::string("--gt-target"), p.gt_target, std::string("--gt-source"), p.gt_source,
                        std::string("-j"), std::to_string(threads)})
    argv.push_back(a);
  const ChildRun run = runChild(argv, timeout_s);
  row.exit_code = run.exit_code;
  row.seconds = run.seconds;
  row.cpu_seconds = run.cpu_seconds;
  row.peak_rss_mb = run.peak_rss_mb;
  if (run.timed_out) {
    row.note = "timed out after " + shortNumber(timeout_s) + " s";
    return row;
  }
  if (candidates && fs::exists(json)) {
    fs::create_directories(scratch / "results");
    fs::copy_file(json, scratch / "results" / (fileNameOf(p.name + "." + method) + ".json"),
                  fs::copy_options::overwrite_existing);
  }
  std::ifstream in(json);
  if (run.exit_code > 1 || !in) {
    row.note = run.output.substr(0, run.output.find('\n'));
    return row;
  }
  const auto j = nlohmann::json::parse(in);
  row.reliable = j.value("reliable", false);
  if (j.contains("error")) {
    row.translation_error = j["error"]["translation"];
    row.origin_error = j["error"].value("translation_at_origin", NAN);
    row.yaw_error = j["error"]["yaw"];
    row.success = j["error"]["success"];
  }
  if (!row.reliable) row.note = j.value("reason", "");
  const auto& s = j["slices"];
  row.features = s.value("target_features", 0.0) + s.value("source_features", 0.0);
  row.slices = s.value("target", 0.0) + s.value("source", 0.0);
  row.raw_bytes =
      static_cast<double>(kPcdBytesPerPoint) * (j.value("target_points", 0.0) + j.value("source_points", 0.0));
  if (method == "tomomap")
    row.payload_bytes = static_cast<double>(transport::kFeatureBytes) * row.features + kBytesPerSlice * row.slices;
  return row;
}

std::string summary(const std::string& suite, const std::vector<Row>& rows, const std::vector<std::string>& skipped) {
  std::map<std::pair<std::string, std::string>, std::vector<const Row*>> groups;
  for (const auto& r : rows) groups[{r.method, r.noise}].push_back(&r);
  std::ostringstream o;
  o << std::fixed;
  o << "## " << suite << "\n\n"
    << "| method | noise | pairs | success | median t err [m] | p90 t err [m] | median yaw err [rad] | p90 yaw err "
       "[rad] | median time [s] | peak RSS [MB] | payload / raw map |\n"
    << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::map<std::string, std::vector<double>> times, rss;
  for (const auto& [key, g] : groups) {
    std::vector<double> te, ye, t, m;
    int ok = 0;
    double payload = 0, raw = 0;
    for (const Row* r : g) {
      ok += r->success;
      te.push_back(r->success || r->reliable ? r->translation_error : NAN);
      ye.push_back(r->success || r->reliable ? r->yaw_error : NAN);
      t.push_back(r->seconds);
      m.push_back(r->peak_rss_mb);
      payload += r->payload_bytes;
      raw += r->raw_bytes;
      times[key.first].push_back(r->seconds);
      rss[key.first].push_back(r->peak_rss_mb);
    }
    o << "| " << key.first << " | " << key.second << " | " << g.size() << " | " << ok << "/" << g.size() << " | "
      << std::setprecision(3) << quantile(te, 0.5) << " | " << quantile(te, 0.9) << " | " << std::setprecision(4)
      << quantile(ye, 0.5) << " | " << quantile(ye, 0.9) << " | " << std::setprecision(2) << quantile(t, 0.5) << " | "
      << std::setprecision(0) << quantile(m, 1.0) << " | ";
    if (payload > 0 && raw > 0)
      o << std::setprecision(1) << 100.0 * payload / raw << " %";
    else
      o << "–";
    o << " |\n";
  }
  // Each family (a world at a grid, a real scan, the listed pairs) as a
  // regression matrix reads it: a refusal of a right answer counts against
  // the method as much as a wrong answer does, so both are shown.
  std::map<std::pair<std::string, std::string>, std::array<int, 4>> families;  // right, refused, wrong, errors
  for (const auto& r : rows) {
    auto& f = families[{r.method, r.family}];
    ++f[r.success ? 0 : r.exit_code == kExitNoMatch ? 1 : r.exit_code == kExitOk ? 2 : 3];
  }
  o << "\n| method | family | pairs | right | refused | wrong | errors |\n|---|---|---|---|---|---|---|\n";
  for (const auto& [key, f] : families)
    o << "| " << key.first << " | " << key.second << " | " << f[0] + f[1] + f[2] + f[3] << " | " << f[0] << " | "
      << f[1] << " | " << f[2] << " | " << f[3] << " |\n";
  if (!skipped.empty()) {
    o << "\nSkipped (no pair to match, not counted above):\n";
    for (const auto& s : skipped) o << "- " << s << "\n";
  }
  if (times.count("tomomap") && times.count("fpfh-ransac")) {
    o << std::setprecision(1) << "\nfpfh-ransac / tomomap: median time "
      << quantile(times["fpfh-ransac"], 0.5) / quantile(times["tomomap"], 0.5) << "x, peak memory "
      << quantile(rss["fpfh-ransac"], 1.0) / quantile(rss["tomomap"], 1.0) << "x\n";
  }
  return o.str();
}

/// The paper's figures: errors, time and memory per method and noise level.
/// Errors are in grid cells and degrees so one success threshold fits pairs of
/// any grid size; failed runs count at their error (a no-match has none).
cv::Mat boxPlots(const std::vector<Row>& rows, const std::vector<std::string>& methods) {
  std::vector<std::string> noise;
  for (const char* n : {"none", "low", "high", "real"})
    for (const auto& r : rows)
      if (r.noise == n) {
        noise.push_back(n);
        break;
      }
  viz::BoxPanel t{
      "translation error", "error / grid size [cells]", true, 5.0, "success limit 5 cells", noise, methods, {}};
  viz::BoxPanel y{"yaw error", "error [deg]", true, 10.0, "success limit 10 deg", noise, methods, {}};
  viz::BoxPanel w{"wall time per pair", "time [s]", true, NAN, "", noise, methods, {}};
  viz::BoxPanel m{"peak memory per pair", "peak RSS [MB]", false, NAN, "", noise, methods, {}};
  for (const auto& r : rows) {
    const std::pair<std::string, std::string> key{r.noise, r.method};
    t.values[key].push_back(r.translation_error / r.grid);
    y.values[key].push_back(degrees(r.yaw_error));
    w.values[key].push_back(r.seconds);
    m.values[key].push_back(r.peak_rss_mb);
  }
  return viz::stack(
      {viz::stack({drawBoxPanel(t), drawBoxPanel(y)}, false), viz::stack({drawBoxPanel(w), drawBoxPanel(m)}, false)});
}

struct EvalOptions {
  std::string suite, out = "eval-out";
  SuiteSequence sequence;  ///< a user's own posed sequence, instead of a suite (--scans, --poses)
  int sequence_pairs = 10;
  std::vector<std::string> methods;
  int threads = 0;
  double timeout_s = 0;     ///< per run; 0 = none
  bool candidates = false;  ///< tomomap's runs list their candidates; every run's JSON kept in OUT/results
};

/// The suite a user's own posed sequence stands for: `pairs` seeds of it, tomomap alone.
Suite sequenceSuite(SuiteSequence q, int pairs) {
  Suite s;
  if (q.name.empty()) q.name = sequenceName(q.scans);
  s.name = q.name;
  s.methods = {"tomomap"};
  q.seeds.clear();
  for (int seed = 1; seed <= pairs; ++seed) q.seeds.push_back(seed);
  s.sequences.push_back(q);
  return s;
}

int runEval(const EvalOptions& o) {
  if (o.suite.empty() == o.sequence.scans.empty())
    throw InputError("give a suite file, or a sequence as --scans DIR --poses FILE (not both)");
  if (!o.sequence.scans.empty() && o.sequence.poses.empty()) throw InputError("--scans needs --poses");
  Suite suite = o.suite.empty() ? sequenceSuite(o.sequence, o.sequence_pairs) : loadSuite(o.suite);
  if (!o.methods.empty()) {
    suite.methods = o.methods;
    // The command line decides for every pair.
    for (auto& y : suite.synth) y.methods.clear();
    for (auto& c : suite.scans) c.methods.clear();
    for (auto& q : suite.sequences) q.methods.clear();
  }
  for (const auto& w : suite.warnings) std::cerr << "tomomap eval: warning: " << w << "\n";
  const fs::path out(o.out);
  std::error_code ec;
  fs::create_directories(out / "worlds", ec);
  if (ec) throw InputError(o.out + ": cannot create the output folder: " + ec.message());

  // A world is generated once however many blocks match it (at other grids).
  std::map<std::string, GeneratedWorld> worlds;
  for (const auto& y : suite.synth)
    for (const auto& noise : y.noise)
      for (int64_t seed : y.seeds) {
        synth::SceneParams sp;
        sp.type = synth::parseWorldType(y.world);
        sp.seed = static_cast<uint64_t>(seed);
        sp.scale = y.scale;
        sp.tilt = radians(y.tilt_deg);
        std::string world = y.world + "-" + noise + "-" + std::to_string(seed);
        std::string variant;  // what the family adds to the world type
        if (y.scale != 1.0) variant += " x" + shortNumber(y.scale);
        if (y.tilt_deg != 0.0) variant += " tilt" + shortNumber(y.tilt_deg);
        for (char c : variant) world += c == ' ' ? '-' : c;
        if (!worlds.count(world)) {
          std::cerr << "generating " << world << "\n";
          worlds[world] = writeSynthWorld(sp, synth::noiseLevel(noise), (out / "worlds" / world).string());
        }
        const GeneratedWorld& w = worlds[world];
        const double grid = y.grid > 0 ? y.grid : w.grid;
        const std::string name = y.grid > 0 ? world + "-g" + shortNumber(y.grid) : world;
        suite.pairs.push_back({name, w.maps[0], w.maps[1], w.poses[0], w.poses[1], grid, noise,
                               y.world + " g" + shortNumber(grid) + variant, y.methods});
      }
  // A seed whose cut leaves too small a crop is no pair: said and skipped, so
  // one seed does not end a run of hundreds (a scan that cannot be read still does).
  std::vector<std::string> skipped;
  for (const auto& c : suite.scans)
    for (int64_t seed : c.seeds) {
      synth::ScanPairParams params;
      params.seed = static_cast<uint64_t>(seed);
      params.move_xy = c.move;
      const std::string folder = c.name + "-" + std::to_string(seed) + "-g" + shortNumber(c.grid);
      std::cerr << "cutting " << folder << " from " << c.file << "\n";
      std::string what;
      GeneratedWorld w;
      try {
        w = writeScanPair(c.file, params, (out / "worlds" / folder).string(), &what);
      } catch (const synth::SmallCrop& e) {
        skipped.push_back(folder + ": " + e.what());
        std::cerr << "tomomap eval: warning: skipping " << skipped.back() << "\n";
        continue;
      }
      suite.pairs.push_back({folder + "-" + what, w.maps[0], w.maps[1], w.poses[0], w.poses[1], c.grid, "real",
                             c.name + " g" + shortNumber(c.grid), c.methods});
    }

  // A sequence is read, and its up found, once for all its blocks and seeds.
  std::map<std::pair<std::string, std::string>, std::vector<PosedScan>> sequences;
  std::map<std::tuple<std::string, std::string, double>, Eigen::Vector3d> ups;
  for (const auto& q : suite.sequences)
    for (int64_t seed : q.seeds) {
      synth::SequencePairParams params;
      params.seed = static_cast<uint64_t>(seed);
      params.level = q.level;
      params.turn_deg = q.turn;
      params.max_range = q.range;
      params.move_xy = q.move;
      auto& scans = sequences[{q.scans, q.poses}];
      if (scans.empty()) {
        std::cerr << "reading the sequence " << q.scans << " posed by " << q.poses << "\n";
        scans = loadPosedScans(q.scans, q.poses);
      }
      const auto up_key = std::make_tuple(q.scans, q.poses, q.range);
      // Leaning maps need the up only to say how far they lean: a sequence
      // whose floors do not tell it is still cut, its leans unknown (null).
      if (!ups.count(up_key)) try {
          ups[up_key] = synth::sequenceUp(scans, params);
        } catch (const InputError&) {
          ups[up_key] = Eigen::Vector3d::Constant(NAN);
        }
      if ((q.level || q.turn != 0) && !ups[up_key].allFinite())
        throw InputError(q.scans +
                         ": the sequence's flat surfaces do not tell its up direction: its maps cannot be "
                         "levelled (level = false cuts them as they lean)");
      const std::string variant = q.turn != 0 ? "turned" + shortNumber(q.turn) : q.level ? "level" : "lean";
      const std::string folder = q.name + "-" + std::to_string(seed) + "-g" + shortNumber(q.grid) + "-" + variant;
      std::cerr << "cutting " << folder << "\n";
      std::string what;
      GeneratedWorld w;
      try {
        w = writeSequencePair(scans, ups[up_key], params, (out / "worlds" / folder).string(), &what);
      } catch (const synth::SmallCrop& e) {
        skipped.push_back(folder + ": " + e.what());
        std::cerr << "tomomap eval: warning: skipping " << skipped.back() << "\n";
        continue;
      }
      suite.pairs.push_back({q.name + "-" + std::to_string(seed) + "-g" + shortNumber(q.grid) + "-" + what, w.maps[0],
                             w.maps[1], w.poses[0], w.poses[1], q.grid, "real",
                             q.name + " g" + shortNumber(q.grid) +
                                 (q.turn != 0 ? " turned " + shortNumber(q.turn)
                                  : q.level   ? " levelled"
                                              : " leaning"),
                             q.methods});
    }

  std::ofstream rows_csv(out / "rows.csv");
  std::ofstream rows_json(out / "rows.jsonl");
  rows_csv << kCsvHeader << "\n";
  std::vector<Row> rows;
  auto methodsOf = [&](const SuitePair& p) { return p.methods.empty() ? suite.methods : p.methods; };
  size_t total = 0;
  for (const auto& p : suite.pairs) total += methodsOf(p).size();
  for (const auto& p : suite.pairs)
    for (const auto& m : methodsOf(p)) {
      // Said before it starts: a baseline run can take minutes.
      std::cerr << "[" << rows.size() + 1 << "/" << total << "] " << p.name << " " << m << ": running\n";
      Row r = runOne(p, m, out, o.threads, o.timeout_s, o.candidates);
      rows.push_back(r);
      // Written as they finish: an interrupted run keeps every finished row.
      rows_csv << csv(r) << std::endl;
      rows_json << nlohmann::json{{"schema_version", kJsonSchemaVersion},
                                  {"pair", r.pair},
                                  {"noise", r.noise},
                                  {"family", r.family},
                                  {"method", r.method},
                                  {"exit_code", r.exit_code},
                                  {"reliable", r.reliable},
                                  {"success", r.success},
                                  {"translation_error_m", std::isnan(r.translation_error)
                                                              ? nlohmann::json()
                                                              : nlohmann::json(r.translation_error)},
                                  {"translation_error_at_origin_m",
                                   std::isnan(r.origin_error) ? nlohmann::json() : nlohmann::json(r.origin_error)},
                                  {"yaw_error_rad",
                                   std::isnan(r.yaw_error) ? nlohmann::json() : nlohmann::json(r.yaw_error)},
                                  {"wall_s", r.seconds},
                                  {"cpu_s", r.cpu_seconds},
                                  {"peak_rss_mb", r.peak_rss_mb},
                                  {"features", r.features},
                                  {"feature_payload_bytes", r.payload_bytes},
                                  {"raw_map_bytes", r.raw_bytes},
                                  {"note", r.note}}
                       .dump()
                << std::endl;
      std::cerr << "[" << rows.size() << "/" << total << "] " << std::left << std::setw(28) << p.name << " "
                << std::setw(12) << m
                << (r.success          ? "success"
                    : r.exit_code == 1 ? "no match"
                    : r.exit_code != 0 ? "error"
                                       : "FAILED")
                << std::fixed << std::setprecision(3) << "  t " << r.translation_error << " m  yaw " << r.yaw_error
                << " rad  " << std::setprecision(2) << r.seconds << " s  " << std::setprecision(0) << r.peak_rss_mb
                << " MB" << (r.note.empty() ? "" : "  (" + r.note + ")") << "\n";
    }
  const std::string md = summary(suite.name, rows, skipped);
  std::ofstream(out / "summary.md") << md;
  viz::writePng((out / "boxplots.png").string(), boxPlots(rows, suite.methods));
  std::cout << md << "\nrows: " << (out / "rows.csv").string() << ", summary: " << (out / "summary.md").string()
            << ", plots: " << (out / "boxplots.png").string() << "\n";
  return kExitOk;
}

}  // namespace

Command addEvalCommand(CLI::App& app) {
  auto o = std::make_shared<EvalOptions>();
  CLI::App* sub =
      app.add_subcommand("eval", "Run every pair of a suite through tomomap and the methods it is measured against.");
  sub->add_option("SUITE", o->suite, "suite file (TOML): [[pair]], [[synth]], [[scan]] and [[sequence]] tables");
  // A user's own SLAM output: how tomomap would do on their robots' maps.
  CLI::Option* scans =
      sub->add_option("--scans", o->sequence.scans,
                      "instead of a suite: a folder of keyframe scans (one .pcd/.ply/.xyz a keyframe, in name order), "
                      "cut into two robots' maps per pair")
          ->check(CLI::ExistingDirectory);
  // Said, not ignored, beside a suite file.
  sub->add_option("--poses", o->sequence.poses, "the keyframes' poses (KITTI, TUM or FAST-LIO's format), one a scan")
      ->check(CLI::ExistingFile)
      ->needs(scans);
  sub->add_option("--pairs", o->sequence_pairs, "with --scans: how many pairs to cut (seeds 1..N)")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000))
      ->needs(scans);
  sub->add_option("-g,--grid", o->sequence.grid, "with --scans: grid size to match at [m]")
      ->capture_default_str()
      ->check(gridSize())
      ->needs(scans);
  sub->add_flag("--level", o->sequence.level,
                "with --scans: level each map (as if the SLAM saved it gravity-aligned) instead of leaning as saved")
      ->needs(scans);
  sub->add_option("--range", o->sequence.range, "with --scans: each scan's points kept within this range [m]")
      ->capture_default_str()
      ->check(CLI::PositiveNumber)
      ->needs(scans);
  sub->add_option("-o,--out", o->out, "output directory (rows.csv, rows.jsonl, summary.md, boxplots.png, worlds/)")
      ->capture_default_str();
  sub->add_option("-m,--methods", o->methods, "override the suite's methods (tomomap, fpfh-ransac, paper-consensus)")
      ->check(CLI::IsMember(kEvalMethods));
  sub->add_option("-j,--threads", o->threads, "threads per match (0 = all cores)")
      ->capture_default_str()
      ->check(settingRange("threads"));
  sub->add_option("--timeout", o->timeout_s,
                  "seconds one run may take; then it is killed and its row says so (0 = none)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  sub->add_flag("--candidates", o->candidates,
                "tomomap lists every candidate pose (tomomap match --candidates) and each run's JSON is kept in "
                "OUT/results/: what the decision could have answered, pair by pair");
  return {sub, [o] { return runEval(*o); }};
}

}  // namespace tomomap::cli
