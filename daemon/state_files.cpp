#include "state_files.hpp"

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <stdexcept>

namespace tomomap::daemon {

void writeJsonAtomically(const std::string& path, const nlohmann::json& j) {
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << j.dump(2) << "\n";
    out.flush();
    if (!out) throw std::runtime_error(tmp + ": cannot write");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw std::runtime_error(path + ": cannot replace");
}

std::string versionText(uint64_t version) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(version));
  return buf;
}

nlohmann::json toJson(const wire::TransformEstimate& e) {
  nlohmann::json j{{"target", e.target().to_string()},
                   {"source", e.source().to_string()},
                   {"target_version", versionText(e.target_version())},
                   {"source_version", versionText(e.source_version())},
                   {"reliable", e.reliable()},
                   {"computed_by", e.computed_by().to_string()},
                   {"computed_at_ms", e.computed_at_ms()},
                   {"matching_seconds", e.seconds()}};
  if (e.reliable()) {
    nlohmann::json m = nlohmann::json::array();
    for (int r = 0; r < 4; ++r)
      m.push_back({e.matrix()[4 * r], e.matrix()[4 * r + 1], e.matrix()[4 * r + 2], e.matrix()[4 * r + 3]});
    j["T_target_source"] = {{"x", e.x()}, {"y", e.y()}, {"z", e.z()}, {"yaw", e.yaw()}, {"matrix", m}};
  } else {
    j["reason"] = e.reason().to_string();
  }
  j["quality"] = {{"support", e.support()},
                  {"runner_up_support", e.runner_up_support()},
                  {"inliers", e.inliers()},
                  {"inlier_spread", {e.spread()[0], e.spread()[1], e.spread()[2]}}};
  return j;
}

}  // namespace tomomap::daemon
