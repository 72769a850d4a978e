// What the agent tells its operator: status.json and transforms.json in the
// output directory (read by `tomomap status`), and systemd's STATUS= line.
#include <unistd.h>

#include <filesystem>

#include "agent.hpp"
#include "agent_detail.hpp"
#include "state_files.hpp"

namespace tomomap::daemon {

using namespace detail;
namespace fs = std::filesystem;

void Agent::persist(bool transforms_changed) {
  const fs::path dir(config_.output_dir);
  try {
    if (transforms_changed) {
      nlohmann::json list = nlohmann::json::array();
      for (const auto& [key, e] : results_) list.push_back(toJson(e));
      writeJsonAtomically((dir / "transforms.json").string(), {{"agent", config_.agent()}, {"transforms", list}});
    }
    nlohmann::json peers = nlohmann::json::object();
    for (const auto& peer : config_.transport.peers) {
      nlohmann::json j{{"alive", alive_.count(peer.id) > 0}, {"host", peer.host}, {"port", peer.port}};
      if (const auto seen = last_seen_ms_.find(peer.id); seen != last_seen_ms_.end())
        j["last_seen_ms"] = seen->second;
      const auto it = peers_.find(peer.id);
      if (it != peers_.end() && it->second.incoming) {
        const PeerMap& p = it->second;
        j["version"] = versionText(p.incoming->announcement().version());
        j["slices_received"] = p.incoming->slicesDone();
        j["slices_total"] = p.incoming->sliceCount();
        j["slices_reused"] = p.reused;
        j["bytes_received"] = p.bytes;
        j["samples_received"] = p.samples;
        j["complete"] = p.features != nullptr;
        j["transfer_seconds"] = p.samples ? seconds(p.last_slice - p.requested) : 0.0;
        j["rate_kbps"] = rateKbps(p);
      }
      nlohmann::json history = nlohmann::json::array();
      if (const auto t = transfers_.find(peer.id); t != transfers_.end())
        for (const auto& x : t->second)
          history.push_back({{"version", versionText(x.version)},
                             {"slices", x.slices},
                             {"slices_reused", x.reused},
                             {"bytes", x.bytes},
                             {"seconds", x.seconds}});
      j["transfers"] = history;
      peers[peer.id] = j;
    }
    const auto& a = offer_.announcement;
    nlohmann::json status{{"agent", config_.agent()},
                          {"pid", ::getpid()},
                          {"config", config_.file},
                          {"written_at_ms", wallMs()},
                          {"uptime_s", seconds(Clock::now() - started_)},
                          {"map",
                           {{"path", config_.map},
                            {"version", versionText(a.version())},
                            {"updated_at_ms", map_updated_ms_},
                            {"updating", describing_.valid()},
                            {"slices", a.slices().size()},
                            {"payload_bytes", offer_.payload_bytes},
                            {"raw_bytes", a.raw_bytes()}}},
                          {"bandwidth_kbps", config_.transport.bandwidth_kbps},
                          {"sent", {{"bytes", counters_.bytes_sent}, {"samples", counters_.samples_sent}}},
                          {"peers", peers},
                          {"pairs_agreed", results_.size()},
                          {"matches_computed", counters_.matches_computed},
                          {"computing", computing_ ? pairText(*computing_) : ""},
                          {"dropped_unknown_agent", counters_.unknown_agent},
                          {"rejected_samples", counters_.rejected}};
    writeJsonAtomically((dir / "status.json").string(), status);
  } catch (const std::exception& e) {
    log_.error(std::string("cannot write state: ") + e.what());
  }
}

std::string Agent::statusLine() const {
  const size_t peers = config_.transport.peers.size();
  size_t maps = 0, slices_in = 0, slices_all = 0;
  for (const auto& [id, p] : peers_) {
    if (!p.incoming) continue;
    maps += p.features != nullptr;
    slices_in += p.incoming->slicesDone();
    slices_all += p.incoming->sliceCount();
  }
  // Pairs among this agent and its peers, and how many of them are current.
  const size_t pairs = (peers + 1) * peers / 2;
  size_t agreed = 0;
  for (const auto& [key, e] : results_) agreed += isCurrent(e);
  std::string line = std::to_string(alive_.size()) + "/" + std::to_string(peers) + " peers up; " +
                     std::to_string(maps) + "/" + std::to_string(peers) + " peer maps (" +
                     std::to_string(slices_in) + "/" + std::to_string(slices_all) + " slices); " +
                     std::to_string(agreed) + "/" + std::to_string(pairs) + " pairs agreed; " +
                     std::to_string(counters_.bytes_sent / 1000) + " kB sent";
  if (computing_) line += "; computing " + pairText(*computing_);
  if (describing_.valid()) line += "; describing an updated map";
  return line;
}

}  // namespace tomomap::daemon
