// `tomomap status`: what a running tomomapd is doing, read from the files it
// keeps in its state directory (status.json each second, transforms.json on
// every agreement), so it works without joining the DDS network.
#include <signal.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.hpp"
#include "core/text.hpp"
#include "core/types.hpp"
#include "exit_codes.hpp"
#include "results/agreed_transform.hpp"
#include "results/json_schema.hpp"

namespace tomomap::cli {
namespace {

using nlohmann::json;

/// status.json older than this means the daemon is not serving (it writes every second).
constexpr double kStaleSeconds = 5;

struct StatusOptions {
  std::string dir = "/var/lib/tomomap";
  bool json = false;
};

json readJson(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot read (is tomomapd's output_dir here? try sudo)");
  try {
    return json::parse(in);
  } catch (const json::exception& e) {
    throw InputError(path.string() + ": not valid JSON: " + e.what());
  }
}

double nowMs() {
  return static_cast<double>(
      std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count());
}

std::string ago(double ms) {
  const double s = std::max(0.0, (nowMs() - ms) / 1000);
  if (s < 60) return fixed(s, 1) + " s ago";
  if (s < 3600) return std::to_string(static_cast<int>(s / 60)) + " min ago";
  return fixed(s / 3600, 1) + " h ago";
}

std::string kB(double bytes) { return fixed(bytes / 1000, 1) + " kB"; }

bool processAlive(int pid) { return pid > 0 && (::kill(pid, 0) == 0 || errno == EPERM); }

/// The version each agent's map has now, as far as this daemon knows.
std::map<std::string, uint64_t> currentVersions(const json& status) {
  std::map<std::string, uint64_t> v{{status.value("agent", ""), parseVersion(status["map"].value("version", ""))}};
  for (const auto& [id, p] : status["peers"].items())
    if (p.contains("version")) v[id] = parseVersion(p["version"].get<std::string>());
  return v;
}

/// frame.json's verdict entry for a pair, or null.
const json* verdictOf(const json& frame, const std::string& pair) {
  const auto pairs = frame.find("pairs");  // by reference: the pointer returned points into `frame`
  if (pairs == frame.end() || !pairs->is_array()) return nullptr;
  for (const auto& p : *pairs)
    if (p.value("pair", "") == pair) return &p;
  return nullptr;
}

std::string loopText(const json& verdict) {
  const auto& e = verdict["cycle_error"];
  return chainText(verdict["cycle"].get<std::vector<std::string>>(), /*closed=*/true) + " misses by " +
         fixed(e.value("translation_m", 0.0), 3) + " m, " + fixed(e.value("yaw_deg", 0.0), 2) + " deg";
}

/// The fleet's frame: each agent's pose in the reference's map and how it is reached.
void printFrame(const json& frame) {
  if (!frame.contains("agents")) return;
  std::cout << "  frame (reference " << frame.value("reference", "?") << "; " << frame.value("optimised_pairs", 0)
            << " consistent pairs solved together)\n";
  for (const auto& a : frame["agents"]) {
    const auto& T = a["T_reference_agent"];
    std::cout << "    " << std::left << std::setw(12) << a.value("agent", "") << std::right << "x "
              << fixed(T.value("x", 0.0), 3) << "  y " << fixed(T.value("y", 0.0), 3) << "  z "
              << fixed(T.value("z", 0.0), 3) << "  yaw " << fixed(degrees(T.value("yaw", 0.0)), 2) << " deg   via "
              << chainText(a["path"].get<std::vector<std::string>>()) << "\n";
  }
  for (const auto& id : frame.value("unreachable", json::array()))
    std::cout << "    " << std::left << std::setw(12) << id.get<std::string>() << std::right
              << "not placed: no consistent transform joins it to the reference yet\n";
}

/// The daemon's last build of the fleet's map (status.json's `fleet_map`).
void printFleetMap(const json& status) {
  const json& m = status.value("fleet_map", json());
  if (!m.is_object()) return;
  if (m.contains("error")) {
    std::cout << "  fleet map NOT built: " << m["error"].get<std::string>() << "\n";
    return;
  }
  std::string robots;
  for (const auto& r : m.value("robots", json::array()))
    robots += (robots.empty() ? "" : ", ") + r.value("agent", "?") + " " + std::to_string(r.value("cells", 0));
  std::cout << "  fleet map " << m.value("cells", 0) << " cells in " << m.value("frame", "?") << " (" << robots
            << "), built " << ago(m.value("built_at_ms", 0.0)) << "\n           " << m.value("files", "") << "\n";
}

void printHuman(const json& status, const json& transforms, const json& frame, bool running) {
  const json& map = status["map"];
  std::cout << "tomomapd " << status.value("agent", "?") << ": "
            << (running ? "running (pid " + std::to_string(status.value("pid", 0)) + ", up " +
                              fixed(status.value("uptime_s", 0.0) / 60, 1) + " min)"
                        : "NOT RUNNING")
            << "; status written " << ago(status.value("written_at_ms", 0.0)) << "\n";
  std::cout << "  config   " << status.value("config", "?") << "\n";
  if (map.value("waiting", false))
    std::cout << "  map      " << map.value("path", "?")
              << "\n           WAITING: no usable map file yet, nothing offered\n";
  else
    std::cout << "  map      " << map.value("path", "?") << "\n           version " << map.value("version", "?") << ", "
              << map.value("slices", 0) << " slices, payload " << kB(map.value("payload_bytes", 0.0)) << " ("
              << fixed(100.0 * map.value("payload_bytes", 0.0) / std::max(1.0, map.value("raw_bytes", 1.0)), 1)
              << " % of the map's binary PCD)" << (map.value("updating", false) ? ", an update is being described" : "")
              << "\n";
  if (map.contains("tilt_deg") && map["tilt_deg"].is_number())
    std::cout << "           tilt " << fixed(map["tilt_deg"].get<double>(), 1) << " deg\n";
  if (!map.value("update_refused", std::string()).empty())
    std::cout << "           the map file's new content is NOT offered: " << map["update_refused"].get<std::string>()
              << "\n";
  std::cout << "  sent     " << kB(status["sent"].value("bytes", 0.0)) << " in " << status["sent"].value("samples", 0)
            << " samples, budget " << status.value("bandwidth_kbps", 0.0) << " kbit/s\n";
  std::cout << "  peers\n";
  for (const auto& [id, p] : status["peers"].items()) {
    std::cout << "    " << std::left << std::setw(12) << id << std::right << (p.value("alive", false) ? "up  " : "down")
              << "  " << p.value("host", "") << ":" << p.value("port", 0) << "  last seen "
              << (p.contains("last_seen_ms") ? ago(p["last_seen_ms"].get<double>()) : "never");
    if (p.contains("version"))
      std::cout << "\n        map " << p["version"].get<std::string>() << ": " << p.value("slices_received", 0) << "/"
                << p.value("slices_total", 0) << " slices (" << p.value("slices_reused", 0)
                << " kept from its previous version), " << kB(p.value("bytes_received", 0.0)) << " received"
                << (p.value("complete", false) ? ", complete" : ", in transfer") << ", "
                << fixed(p.value("rate_kbps", 0.0), 0) << " kbit/s";
    if (p.contains("incompatible")) std::cout << "\n        INCOMPATIBLE: " << p["incompatible"].get<std::string>();
    std::cout << "\n";
  }
  const auto versions = currentVersions(status);
  const json& list = transforms["transforms"];
  std::cout << "  transforms (" << list.size() << ")\n";
  for (const auto& entry : list) {
    const AgreedTransform t = agreedFromJson(entry);
    std::cout << "    " << t.target << " <- " << t.source << "  ";
    if (t.reliable) {
      const Pose4& T = t.T_target_source;
      std::cout << "x " << fixed(T.x, 3) << "  y " << fixed(T.y, 3) << "  z " << fixed(T.z, 3) << "  yaw "
                << fixed(degrees(T.yaw), 2) << " deg";
    } else {
      std::cout << "no reliable match: " << t.reason;
    }
    std::cout << "\n        ";
    if (t.reliable) std::cout << "answered by " << t.answered_by << ", " << fixed(t.lead_sigma, 1) << " sigma clear; ";
    std::cout << "computed by " << t.computed_by << " in " << fixed(t.seconds, 2) << " s, "
              << ago(static_cast<double>(t.computed_at_ms));
    const bool current =
        versions.count(t.target) && versions.count(t.source) && t.isFor(versions.at(t.target), versions.at(t.source));
    std::string kept;
    for (const auto& p : status.value("pairs", json::array()))
      if (p.value("pair", "") == t.target + "<-" + t.source && p.value("state", "") == "kept")
        kept = p.value("why", "");
    if (!kept.empty())
      std::cout << "; KEPT: for earlier maps; the current ones gave no reliable match (" << kept << ")";
    else if (!current)
      std::cout << "; STALE: a map changed since, recomputing";
    if (const json* v = t.reliable ? verdictOf(frame, t.target + "<-" + t.source) : nullptr) {
      const std::string verdict = v->value("verdict", "");
      if (verdict == "inconsistent")
        std::cout << "\n        INCONSISTENT with the fleet's other transforms: the loop " << loopText(*v)
                  << "; left out of the frame";
      else if (verdict == "consistent")
        std::cout << "\n        consistent: the loop " << loopText(*v);
      else
        std::cout << "\n        unchecked: on no loop of transforms";
    }
    std::cout << "\n";
  }
  printFrame(frame);
  printFleetMap(status);
}

int runStatus(const StatusOptions& o) {
  const std::filesystem::path dir(o.dir);
  const json status = readJson(dir / "status.json");
  json transforms = std::filesystem::exists(dir / "transforms.json") ? readJson(dir / "transforms.json")
                                                                     : json{{"transforms", json::array()}};
  if (!status.contains("map") || !status.contains("peers") || !transforms["transforms"].is_array())
    throw InputError((dir / "status.json").string() + ": not a tomomapd status file");
  const json frame = std::filesystem::exists(dir / "frame.json") ? readJson(dir / "frame.json") : json::object();
  const bool fresh = (nowMs() - status.value("written_at_ms", 0.0)) / 1000 < kStaleSeconds;
  const bool running = fresh && processAlive(status.value("pid", 0));
  if (o.json) {
    std::cout << json{{"schema_version", kJsonSchemaVersion},
                      {"running", running},
                      {"status", status},
                      {"transforms", transforms["transforms"]},
                      {"frame", frame}}
                     .dump(2)
              << "\n";
  } else {
    printHuman(status, transforms, frame, running);
  }
  return running ? kExitOk : kExitNoMatch;
}

}  // namespace

Command addStatusCommand(CLI::App& app) {
  auto o = std::make_shared<StatusOptions>();
  CLI::App* sub = app.add_subcommand(
      "status",
      "Show what a running tomomapd is doing: its map, peers, transfers and agreed transforms.\n"
      "Exit codes: 0 running, 1 not running (the files are from an earlier run), 2 no readable state.");
  sub->add_option("state_dir", o->dir, "the daemon's output_dir (the service's StateDirectory)")->capture_default_str();
  sub->add_flag("--json", o->json, "print one JSON document for scripts instead of text");
  return {sub, [o] {
            if (!o->json) return runStatus(*o);
            // A script reads stdout: it gets a document even when there is no state.
            try {
              return runStatus(*o);
            } catch (const InputError& e) {
              std::cout << json{{"schema_version", kJsonSchemaVersion}, {"running", false}, {"error", e.what()}}.dump(2)
                        << "\n";
              throw;
            }
          }};
}

}  // namespace tomomap::cli
