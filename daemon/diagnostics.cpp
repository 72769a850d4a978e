#include "diagnostics.hpp"

#include <algorithm>

#include "core/text.hpp"

namespace tomomap::daemon {
namespace {

std::string text(const nlohmann::json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }

/// "up, map 3, 120/120 slices" or "down".
std::string peerText(const nlohmann::json& p) {
  std::string s = p.value("alive", false) ? "up" : "down";
  if (p.contains("version"))
    s += ", map " + text(p["version"]) + ", " + text(p.value("slices_received", nlohmann::json(0))) + "/" +
         text(p.value("slices_total", nlohmann::json(0))) + " slices";
  if (p.contains("incompatible")) s += ", incompatible: " + text(p["incompatible"]);
  return s;
}

}  // namespace

transport::Diagnostic diagnosticOf(const nlohmann::json& status, const FleetFrame& frame, const std::string& summary) {
  using transport::Diagnostic;
  Diagnostic d;
  const std::string agent = status.value("agent", "");
  d.name = "tomomapd: " + agent;
  d.hardware_id = agent;
  std::vector<std::string> warnings, errors;

  const nlohmann::json& map = status["map"];
  d.values.emplace_back("map version", text(map.value("version", nlohmann::json(""))));
  d.values.emplace_back("map tilt [deg]", map.contains("tilt_deg") && map["tilt_deg"].is_number()
                                              ? fixed(map["tilt_deg"].get<double>(), 2)
                                              : "not measured");
  d.values.emplace_back("map slices", text(map.value("slices", nlohmann::json(0))));
  if (map.value("waiting", false)) warnings.push_back("its own map is not offered yet");
  if (const std::string refused = map.value("update_refused", ""); !refused.empty())
    warnings.push_back("the map's update is refused: " + refused);

  size_t peers = 0, up = 0;
  for (const auto& [id, p] : status["peers"].items()) {
    ++peers;
    up += p.value("alive", false);
    d.values.emplace_back("peer " + id, peerText(p));
    if (!p.value("alive", false)) warnings.push_back(id + " is down");
    if (p.contains("incompatible")) warnings.push_back(id + " is incompatible");
  }
  d.values.emplace_back("peers up", std::to_string(up) + "/" + std::to_string(peers));

  d.values.emplace_back("pairs agreed", text(status.value("pairs_agreed", nlohmann::json(0))));
  for (const auto& p : status["pairs"]) {
    const std::string pair = p.value("pair", ""), state = p.value("state", "");
    std::string value = state;
    if (p.contains("by")) value += " by " + text(p["by"]);
    if (p.contains("why")) {
      value += ": " + text(p["why"]);
      warnings.push_back(pair + " has no reliable match");
    }
    d.values.emplace_back("pair " + pair, value);
  }
  std::string list;
  for (const auto& v : frame.pairs) {
    if (v.verdict != Consistency::Inconsistent) continue;
    list += (list.empty() ? "" : ", ") + pairText(v.pair);
    warnings.push_back(pairText(v.pair) + " is inconsistent with the fleet's other transforms");
  }
  d.values.emplace_back("inconsistent pairs", list.empty() ? "none" : list);

  d.values.emplace_back("bytes sent", text(status["sent"].value("bytes", nlohmann::json(0))));
  d.values.emplace_back("rejected samples", text(status.value("rejected_samples", nlohmann::json(0))));
  const std::string write_error = status.value("write_error", "");
  d.values.emplace_back("write error", write_error.empty() ? "none" : write_error);
  if (!write_error.empty()) errors.push_back("cannot write transforms.json: " + write_error);

  const std::vector<std::string>& why = errors.empty() ? warnings : errors;
  d.level = !errors.empty() ? Diagnostic::error : !warnings.empty() ? Diagnostic::warn : Diagnostic::ok;
  for (const auto& w : why) d.message += (d.message.empty() ? "" : "; ") + w;
  if (d.message.empty()) d.message = summary;
  return d;
}

}  // namespace tomomap::daemon
