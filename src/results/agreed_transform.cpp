#include "agreed_transform.hpp"

#include <cmath>
#include <cstdio>

#include "core/gravity.hpp"
#include "core/text.hpp"

namespace tomomap {

std::string chainText(const std::vector<std::string>& agents, bool closed) {
  std::string text;
  for (const auto& id : agents) text += (text.empty() ? "" : " -> ") + id;
  if (closed && !agents.empty()) text += " -> " + agents.front();
  return text;
}

std::string versionText(uint64_t version) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(version));
  return buf;
}

uint64_t parseVersion(const std::string& text) {
  if (text.empty() || text.size() > 16 || text.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos)
    throw InputError("'" + text + "' is not a map version (1-16 hex digits)");
  return std::stoull(text, nullptr, 16);
}

AgreedTransform agreedOf(const MatchResult& r, const MapFeatures& target, const MapFeatures& source) {
  AgreedTransform t;
  t.reliable = r.reliable;
  t.reason = r.reason;
  t.T_target_source = r.T_target_source;
  t.target_up = target.slicedUp();
  t.source_up = source.slicedUp();
  t.T_target_source_6dof = r.T_target_source_6dof;
  t.answered_by = fromName(r.answered_by);
  t.lead_sigma = r.lead_sigma;
  return t;
}

Eigen::Matrix4d AgreedTransform::ownFrames() const {
  return T_target_source_6dof.value_or(betweenOwnFrames(T_target_source.matrix(), target_up, source_up));
}

nlohmann::json matrixJson(const Eigen::Matrix4d& M) {
  nlohmann::json m = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) m.push_back({M(r, 0), M(r, 1), M(r, 2), M(r, 3)});
  return m;
}

nlohmann::json upJson(const Eigen::Vector3d& up) { return {up.x(), up.y(), up.z()}; }

Eigen::Vector3d upFromJson(const nlohmann::json& j, const std::string& what) {
  const auto v = j.get<std::array<double, 3>>();
  const Eigen::Vector3d up(v[0], v[1], v[2]);
  if (!levelableUp(up))
    throw InputError(what + " is not a unit vector within " + fixed(degrees(kMaxLevelable), 0) + " deg of z");
  return up;
}

Eigen::Matrix4d matrixFromJson(const nlohmann::json& rows) {
  Eigen::Matrix4d M;
  for (int r = 0; r < 4; ++r) {
    const auto row = rows.at(static_cast<size_t>(r)).get<std::array<double, 4>>();
    for (int c = 0; c < 4; ++c) M(r, c) = row[static_cast<size_t>(c)];
  }
  if (!isRigid(M)) throw InputError("a 4x4 matrix that is not a rotation and a translation");
  return M;
}

nlohmann::json toJson(const Pose4& T) {
  return {{"x", T.x}, {"y", T.y}, {"z", T.z}, {"yaw", T.yaw}, {"matrix", matrixJson(T.matrix())}};
}

bool plausibleQuality(const std::string& answered_by, double lead_sigma) {
  return std::isfinite(lead_sigma) && lead_sigma >= 0 && fromName(answered_by).has_value();
}

nlohmann::json toJson(const AgreedTransform& t) {
  nlohmann::json j{{"target", t.target},
                   {"source", t.source},
                   {"target_version", versionText(t.target_version)},
                   {"source_version", versionText(t.source_version)},
                   {"reliable", t.reliable},
                   {"computed_by", t.computed_by},
                   {"computed_at_ms", t.computed_at_ms},
                   {"matching_seconds", t.seconds}};
  if (t.reliable) {
    j["T_target_source"] = toJson(t.T_target_source);
    j["T_target_source_6dof"] = matrixJson(t.ownFrames());
    j["target_up"] = upJson(t.target_up);
    j["source_up"] = upJson(t.source_up);
  } else {
    j["reason"] = t.reason;
  }
  j["quality"] = {{"answered_by", t.answered_by}, {"lead_sigma", t.lead_sigma}};
  return j;
}

AgreedTransform agreedFromJson(const nlohmann::json& j) {
  try {
    AgreedTransform t;
    t.target = j.at("target").get<std::string>();
    t.source = j.at("source").get<std::string>();
    t.target_version = parseVersion(j.at("target_version").get<std::string>());
    t.source_version = parseVersion(j.at("source_version").get<std::string>());
    t.reliable = j.at("reliable").get<bool>();
    t.computed_by = j.at("computed_by").get<std::string>();
    t.computed_at_ms = j.at("computed_at_ms").get<uint64_t>();
    t.seconds = j.at("matching_seconds").get<double>();
    if (t.reliable) {
      const auto& T = j.at("T_target_source");
      t.T_target_source = {T.at("x").get<double>(), T.at("y").get<double>(), T.at("z").get<double>(),
                           T.at("yaw").get<double>()};
      // Files written before maps were levelled in the fleet have neither: level maps, 4-DoF.
      for (auto [key, up] : {std::pair{"target_up", &t.target_up}, std::pair{"source_up", &t.source_up}})
        if (j.contains(key)) *up = upFromJson(j.at(key), key);
      if (j.contains("T_target_source_6dof")) t.T_target_source_6dof = matrixFromJson(j.at("T_target_source_6dof"));
    } else {
      t.reason = j.value("reason", "");
    }
    // Files of schema 2 weighed pairs by slice pairs, which meant cells for
    // a dense answer: their pairs come back as the least clear answers.
    const auto& q = j.at("quality");
    t.answered_by = q.value("answered_by", fromName(Candidate::From::features));
    t.lead_sigma = q.value("lead_sigma", 0.0);
    if (!plausibleQuality(t.answered_by, t.lead_sigma))
      throw InputError("a quality no match gives: answered_by '" + t.answered_by + "', lead_sigma " +
                       std::to_string(t.lead_sigma));
    return t;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(std::string("not a stored transform: ") + e.what());
  }
}

}  // namespace tomomap
