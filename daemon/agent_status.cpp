// What the agent tells its operator: status.json and transforms.json in the
// output directory (read by `tomomap status`), and systemd's STATUS= line.
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "agent.hpp"
#include "results/json_schema.hpp"
#include "state_files.hpp"

namespace tomomap::daemon {

namespace fs = std::filesystem;

void Agent::agreedChanged() {
  std::vector<AgreedTransform> agreed;
  for (const auto& [key, t] : board_.results()) agreed.push_back(t);
  outputs_.update(std::move(agreed), config_);
  writeStatus(/*retry_outputs=*/false);
}

void Agent::writeStatus(bool retry_outputs) {
  if (retry_outputs) outputs_.retry(config_);
  const fs::path dir(config_.output_dir);
  try {
    nlohmann::json peers = nlohmann::json::object();
    for (const auto& peer : config_.transport.peers) {
      peers[peer.id] = peers_.status(peer);
      if (const auto it = other_grid_.find(peer.id); it != other_grid_.end())
        peers[peer.id]["incompatible"] = it->second;
    }
    const auto now = Clock::now();
    nlohmann::json pairs = nlohmann::json::array();
    for (const auto& key : board_.pairs()) {
      const PairStatus s = board_.status(key, now);
      nlohmann::json p{{"pair", pairText(key)}, {"state", stateName(s.state)}};
      if (!s.by.empty()) p["by"] = s.by;
      if (!s.why.empty()) p["why"] = s.why;
      pairs.push_back(p);
    }
    const auto& offer = sender_.offer();
    const auto egress = bus_ ? bus_->egress() : transport::Bus::Egress{};
    const auto& a = offer.announcement;
    const auto& computing = board_.computing();
    nlohmann::json status{
        {"schema_version", kJsonSchemaVersion},
        {"agent", config_.agent()},
        {"pid", ::getpid()},
        {"config", config_.file},
        {"written_at_ms", wallMs()},
        {"uptime_s", seconds(now - started_)},
        {"map",
         {{"path", mapSource(config_)},
          {"frame_id", map_frame_id_},
          {"version", versionText(a.version())},
          {"updated_at_ms", map_updated_ms_},
          {"updating", describing_.valid()},
          {"waiting", !offering()},
          {"tilt_deg", offering() && own_features_->tilt.measured ? nlohmann::json(degrees(own_features_->tilt.angle))
                                                                  : nlohmann::json()},
          {"levelled", offering() && own_features_->leveled},
          {"up", offering() ? upJson(own_features_->slicedUp()) : nlohmann::json()},
          {"update_refused", map_refused_},
          {"slices", a.slices().size()},
          {"payload_bytes", offer.payload_bytes},
          {"raw_bytes", a.raw_bytes()}}},
        {"bandwidth_kbps", config_.transport.bandwidth_kbps},
        {"sent", {{"bytes", sender_.bytesSent()}, {"samples", sender_.samplesSent()}}},
        {"egress", {{"wire_bytes", egress.wire_bytes}, {"dropped_datagrams", egress.dropped_datagrams}}},
        {"peers", peers},
        {"pairs", pairs},
        {"pairs_agreed", board_.results().size()},
        {"matches_computed", counters_.matches_computed},
        {"computing", computing ? pairText(computing->pair) : ""},
        {"dropped_unknown_agent", counters_.unknown_agent},
        {"rejected_samples", counters_.rejected},
        {"dropped_impostor_samples", counters_.impostors},
        {"refused_participants", counters_.refused_participants},
        {"secure", config_.transport.security.enabled()},
        {"transforms_unwritten", outputs_.unwritten()},
        {"write_error", outputs_.writeError()},
        {"fleet_map", fleetMapStatus()}};
    publishDiagnostics(status);
    writeJsonAtomically((dir / "status.json").string(), status);
    status_unwritten_ = false;
  } catch (const std::exception& e) {
    if (!status_unwritten_) log_.error(std::string("cannot write status.json (retrying): ") + e.what());
    status_unwritten_ = true;
  }
}

void Agent::restoreTransforms() {
  const fs::path path = fs::path(config_.output_dir) / "transforms.json";
  if (!fs::exists(path)) return;
  size_t restored = 0, foreign = 0;
  try {
    std::ifstream in(path);
    const nlohmann::json j = nlohmann::json::parse(in);
    for (const auto& entry : j.at("transforms")) {
      AgreedTransform t = agreedFromJson(entry);
      if (!config_.inFleet(t.target) || !config_.inFleet(t.source)) {
        ++foreign;  // a peer no longer in the config
        continue;
      }
      board_.restore(std::move(t));
      ++restored;
    }
  } catch (const std::exception& e) {
    // Kept for whoever wants to look; the fleet computes the pairs again.
    const std::string aside = path.string() + ".unreadable";
    std::error_code ec;
    fs::rename(path, aside, ec);
    log_.warning(path.string() + " cannot be read (" + e.what() + "): moved to " + aside +
                 "; starting with no stored transforms");
    return;
  }
  log_.info("restored " + std::to_string(restored) + " transforms from " + path.string() +
            (foreign ? " (" + std::to_string(foreign) + " of agents no longer in the config left out)" : "") +
            "; each stays agreed while its maps' versions are the ones announced");
}

std::string Agent::statusLine() const {
  const size_t peers = config_.transport.peers.size();
  const PeerMaps::Totals in = peers_.totals();
  // Pairs among this agent and its peers, and how many of them are current.
  const size_t pairs = (peers + 1) * peers / 2;
  std::string line = offering() ? "" : waitingText() + "; ";
  line += std::to_string(peers_.aliveCount()) + "/" + std::to_string(peers) + " peers up; " + std::to_string(in.maps) +
          "/" + std::to_string(peers) + " peer maps (" + std::to_string(in.slices_done) + "/" +
          std::to_string(in.slices_all) + " slices); " + std::to_string(board_.currentResults()) + "/" +
          std::to_string(pairs) + " pairs agreed; " + std::to_string(sender_.bytesSent() / 1000) + " kB sent";
  if (const auto& c = board_.computing()) line += "; computing " + pairText(c->pair);
  if (describing_.valid()) line += "; describing an updated map";
  return line;
}

}  // namespace tomomap::daemon
