#include "fleet_frame.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <deque>
#include <map>
#include <set>

namespace tomomap {

const char* consistencyName(Consistency c) {
  switch (c) {
    case Consistency::Consistent:
      return "consistent";
    case Consistency::Inconsistent:
      return "inconsistent";
    case Consistency::Unchecked:
      return "unchecked";
  }
  return "?";
}

const AgentPose* FleetFrame::pose(const std::string& agent) const {
  for (const auto& p : poses)
    if (p.agent == agent) return &p;
  return nullptr;
}

Eigen::Matrix4d FleetFrame::ownFramePose(const AgentPose& p) const {
  const AgentPose* r = pose(reference);
  return betweenOwnFrames(p.T_reference_agent.matrix(), r ? r->up : Eigen::Vector3d::UnitZ(), p.up);
}

const PairVerdict* FleetFrame::verdict(const PairKey& pair) const {
  for (const auto& v : pairs)
    if (v.pair == pair) return &v;
  return nullptr;
}

namespace {

/// The reliable pairs as a graph whose links can be set aside.
class PairGraph {
 public:
  explicit PairGraph(std::vector<AgreedTransform> links) : links_(std::move(links)), active_(links_.size(), true) {
    for (size_t e = 0; e < links_.size(); ++e) {
      adjacent_[links_[e].target].push_back(e);
      adjacent_[links_[e].source].push_back(e);
    }
  }
  size_t size() const { return links_.size(); }
  const AgreedTransform& link(size_t e) const { return links_[e]; }
  bool active(size_t e) const { return active_[e]; }
  void setAside(size_t e) { active_[e] = false; }

  /// T_from_to over link `e`, which joins `from` to the other end.
  Pose4 across(size_t e, const std::string& from) const {
    return links_[e].target == from ? links_[e].T_target_source : links_[e].T_target_source.inverse();
  }
  const std::string& otherEnd(size_t e, const std::string& from) const {
    return links_[e].target == from ? links_[e].source : links_[e].target;
  }

  /// The links of the fewest-hop path from `from` to `to` over active links
  /// but `skip`, in order; none when there is no such path. Breadth-first in
  /// key order, so every agent finds the same path.
  std::optional<std::vector<size_t>> path(const std::string& from, const std::string& to, size_t skip) const {
    std::map<std::string, size_t> via;  // agent -> link it was reached over
    std::deque<std::string> queue{from};
    std::set<std::string> seen{from};
    while (!queue.empty() && !seen.count(to)) {
      const std::string at = queue.front();
      queue.pop_front();
      const auto it = adjacent_.find(at);
      if (it == adjacent_.end()) continue;
      for (const size_t e : it->second) {
        if (e == skip || !active_[e]) continue;
        const std::string& next = otherEnd(e, at);
        if (!seen.insert(next).second) continue;
        via[next] = e;
        queue.push_back(next);
      }
    }
    if (!seen.count(to)) return std::nullopt;
    std::vector<size_t> links;
    for (std::string at = to; at != from; at = otherEnd(via.at(at), at)) links.push_back(via.at(at));
    std::reverse(links.begin(), links.end());
    return links;
  }

  /// A loop through link `e`: the way back from its source to its target
  /// over `other` (links from target to source), and how far it misses closing.
  struct Loop {
    PairVerdict verdict;
    std::vector<size_t> links;  ///< every link on it, `e` last
  };
  Loop loopOf(size_t e, const std::vector<size_t>& other) const {
    const AgreedTransform& t = links_[e];
    PairVerdict v;
    v.pair = t.pair();
    Pose4 around;  // T_target_source along the other path
    std::string at = t.target;
    v.cycle.push_back(at);
    for (const size_t step : other) {
      around = around * across(step, at);
      at = otherEnd(step, at);
      v.cycle.push_back(at);
    }
    const Pose4 miss = around.inverse() * t.T_target_source;
    v.cycle_translation = std::sqrt(miss.x * miss.x + miss.y * miss.y + miss.z * miss.z);
    v.cycle_yaw = std::abs(miss.yaw);
    std::vector<size_t> on = other;
    on.push_back(e);
    return Loop{std::move(v), std::move(on)};
  }

  /// The loops through active link `e` that the checks look at: the one over
  /// the shortest other path, and every triangle (a third map both overlap;
  /// the shortest loop may be one of them again).
  std::vector<Loop> loopsThrough(size_t e) const {
    std::vector<Loop> loops;
    const AgreedTransform& t = links_[e];
    if (const auto shortest = path(t.target, t.source, e)) loops.push_back(loopOf(e, *shortest));
    for (const size_t a : adjacent_.at(t.target)) {
      if (a == e || !active_[a]) continue;
      const std::string& third = otherEnd(a, t.target);
      for (const size_t b : adjacent_.at(third))
        if (b != a && active_[b] && otherEnd(b, third) == t.source) loops.push_back(loopOf(e, {a, b}));
    }
    return loops;
  }

 private:
  std::vector<AgreedTransform> links_;
  std::vector<bool> active_;
  std::map<std::string, std::vector<size_t>> adjacent_;
};

bool closes(const PairVerdict& v, const CycleLimits& limits) {
  return v.cycle_translation <= limits.translation && v.cycle_yaw <= limits.yaw;
}

/// Sets aside, one at a time, the link whose loops fail most often (then
/// the one on more failing loops, then the least clear (lead_sigma), then the first
/// by key) until every loop closes. A wrong link fails every loop it is on;
/// a right one only those it shares with a wrong one. Returns the verdict of
/// each link set aside: the first failing loop it was on.
std::map<size_t, PairVerdict> setAsideContradictions(PairGraph& g, const CycleLimits& limits) {
  std::map<size_t, PairVerdict> aside;
  for (;;) {
    std::vector<int> failing(g.size(), 0), checked(g.size(), 0);
    std::map<size_t, PairVerdict> first_failing;
    std::set<std::vector<size_t>> seen;  // each loop once, whichever link found it
    for (size_t e = 0; e < g.size(); ++e) {
      if (!g.active(e)) continue;
      for (const auto& loop : g.loopsThrough(e)) {
        std::vector<size_t> key = loop.links;
        std::sort(key.begin(), key.end());
        if (!seen.insert(key).second) continue;
        const bool fails = !closes(loop.verdict, limits);
        for (const size_t on : loop.links) {
          ++checked[on];
          if (!fails) continue;
          ++failing[on];
          first_failing.emplace(on, loop.verdict);
        }
      }
    }
    std::optional<size_t> worst;
    const auto worse = [&](size_t a, size_t b) {  // a before b?
      const long lhs = static_cast<long>(failing[a]) * checked[b], rhs = static_cast<long>(failing[b]) * checked[a];
      if (lhs != rhs) return lhs > rhs;
      if (failing[a] != failing[b]) return failing[a] > failing[b];
      return g.link(a).lead_sigma < g.link(b).lead_sigma;
    };
    for (size_t e = 0; e < g.size(); ++e)
      if (failing[e] > 0 && (!worst || worse(e, *worst))) worst = e;
    if (!worst) return aside;
    g.setAside(*worst);
    PairVerdict v = first_failing.at(*worst);
    v.pair = g.link(*worst).pair();
    v.verdict = Consistency::Inconsistent;
    aside.emplace(*worst, std::move(v));
  }
}

/// How far T_target_source is from what the two poses say, in units of the limits.
struct PairResidual {
  Pose4 measured;
  CycleLimits limits;

  template <typename T>
  bool operator()(const T* target, const T* source, T* r) const {
    using std::atan2, std::cos, std::sin;
    const T c = cos(target[3]), s = sin(target[3]);
    const T dx = source[0] - target[0], dy = source[1] - target[1], dz = source[2] - target[2];
    r[0] = (c * dx + s * dy - T(measured.x)) / limits.translation;
    r[1] = (-s * dx + c * dy - T(measured.y)) / limits.translation;
    r[2] = (dz - T(measured.z)) / limits.translation;
    const T dyaw = source[3] - target[3] - T(measured.yaw);
    r[3] = atan2(sin(dyaw), cos(dyaw)) / limits.yaw;
    return true;
  }
};

/// Refines `poses` (the reference's held fixed) over the active links: least
/// squares weighted by how clearly each pair's match singled its answer out
/// (lead_sigma, at least 1), Huber beyond the limits so that a bad link
/// the cycle checks could not see (on no loop) pulls less.
bool optimise(const PairGraph& g, const std::string& reference, std::map<std::string, Pose4>& poses,
              const CycleLimits& limits, size_t& used) {
  std::map<std::string, std::array<double, 4>> blocks;
  for (const auto& [agent, p] : poses) blocks[agent] = {p.x, p.y, p.z, p.yaw};
  ceres::Problem problem;
  used = 0;
  for (size_t e = 0; e < g.size(); ++e) {
    const AgreedTransform& t = g.link(e);
    if (!g.active(e) || !blocks.count(t.target) || !blocks.count(t.source)) continue;
    auto* cost = new ceres::AutoDiffCostFunction<PairResidual, 4, 4, 4>(new PairResidual{t.T_target_source, limits});
    auto* loss = new ceres::ScaledLoss(new ceres::HuberLoss(1.0), std::max(1.0, t.lead_sigma), ceres::TAKE_OWNERSHIP);
    problem.AddResidualBlock(cost, loss, blocks[t.target].data(), blocks[t.source].data());
    ++used;
  }
  if (used == 0) return true;
  problem.SetParameterBlockConstant(blocks[reference].data());
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;  // a fleet has tens of agents
  options.max_num_iterations = 200;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  for (auto& [agent, b] : blocks) poses[agent] = {b[0], b[1], b[2], std::atan2(std::sin(b[3]), std::cos(b[3]))};
  return summary.termination_type == ceres::CONVERGENCE;
}

}  // namespace

FleetFrame buildFleetFrame(const std::vector<AgreedTransform>& agreed, const std::vector<std::string>& agents,
                           const std::string& reference, const CycleLimits& limits) {
  std::map<PairKey, AgreedTransform> reliable;  // one per pair, by key: the same order on every agent
  for (const auto& t : agreed)
    if (t.reliable) reliable[t.pair()] = t;
  // One up a map: its newest link's (a map kept for an earlier version may
  // have been levelled by another up). Every link is stated between the maps
  // levelled by those ups, where the 4-DoF graph holds.
  std::map<std::string, std::pair<uint64_t, Eigen::Vector3d>> newest;
  const auto note = [&](const std::string& agent, uint64_t at, const Eigen::Vector3d& up) {
    const auto it = newest.find(agent);
    if (it == newest.end() || at > it->second.first) newest[agent] = {at, up};
  };
  for (const auto& [key, t] : reliable) {
    note(t.target, t.computed_at_ms, t.target_up);
    note(t.source, t.computed_at_ms, t.source_up);
  }
  const auto upOf = [&](const std::string& agent) {
    const auto it = newest.find(agent);
    return it == newest.end() ? Eigen::Vector3d(Eigen::Vector3d::UnitZ()) : it->second.second;
  };
  for (auto& [key, t] : reliable) {
    const Eigen::Vector3d target_up = upOf(t.target), source_up = upOf(t.source);
    if (target_up == t.target_up && source_up == t.source_up) continue;
    // p_target_levelled = R_target * T_own * R_source^-1 p_source_levelled: its nearest 4-DoF.
    t.T_target_source =
        Pose4::fromMatrix(levelingMatrix(target_up) * t.ownFrames() * levelingMatrix(source_up).transpose());
    t.target_up = target_up;
    t.source_up = source_up;
  }
  std::vector<AgreedTransform> links;
  for (auto& [key, t] : reliable) links.push_back(std::move(t));
  PairGraph g(std::move(links));

  FleetFrame frame;
  frame.reference = reference;
  const std::map<size_t, PairVerdict> aside = setAsideContradictions(g, limits);
  for (size_t e = 0; e < g.size(); ++e) {
    if (const auto it = aside.find(e); it != aside.end()) {
      frame.pairs.push_back(it->second);
      continue;
    }
    const auto loops = g.loopsThrough(e);  // all close now: the shortest is shown
    PairVerdict v = loops.empty() ? PairVerdict{g.link(e).pair(), Consistency::Unchecked, {}, 0, 0} : loops[0].verdict;
    if (!loops.empty()) v.verdict = Consistency::Consistent;
    frame.pairs.push_back(std::move(v));
  }

  // Start from the tree of the clearest links over the consistent pairs.
  std::vector<AgreedTransform> kept;
  for (size_t e = 0; e < g.size(); ++e)
    if (g.active(e)) kept.push_back(g.link(e));
  std::map<std::string, Pose4> poses{{reference, Pose4{}}};
  std::map<std::string, std::vector<std::string>> paths{{reference, {reference}}};
  for (const TreeEdge& edge : spanningTree(kept, reference)) {
    poses[edge.child] = poses.at(edge.parent) * edge.T_parent_child;
    paths[edge.child] = paths.at(edge.parent);
    paths[edge.child].push_back(edge.child);
  }
  frame.converged = optimise(g, reference, poses, limits, frame.optimised_pairs);

  frame.poses.push_back({reference, poses.at(reference), upOf(reference), paths.at(reference)});
  std::set<std::string> everyone(agents.begin(), agents.end());
  for (const auto& [key, t] : reliable) everyone.insert({key.first, key.second});
  for (const auto& agent : everyone) {
    if (agent == reference) continue;
    if (poses.count(agent))
      frame.poses.push_back({agent, poses.at(agent), upOf(agent), paths.at(agent)});
    else
      frame.unreachable.push_back(agent);
  }
  return frame;
}

std::vector<TreeEdge> treeOf(const FleetFrame& frame, const std::string& root, uint64_t stamp_ms) {
  const AgentPose* r = frame.pose(root);
  if (!r) return {};
  const Pose4 T_root_reference = r->T_reference_agent.inverse();
  std::vector<TreeEdge> tree;
  for (const auto& p : frame.poses)
    if (p.agent != root) tree.push_back({root, p.agent, T_root_reference * p.T_reference_agent, r->up, p.up, stamp_ms});
  return tree;
}

nlohmann::json toJson(const FleetFrame& frame) {
  nlohmann::json poses = nlohmann::json::array(), pairs = nlohmann::json::array();
  for (const auto& p : frame.poses)
    poses.push_back({{"agent", p.agent},
                     {"T_reference_agent", toJson(p.T_reference_agent)},
                     {"up", upJson(p.up)},
                     {"T_reference_agent_6dof", matrixJson(frame.ownFramePose(p))},
                     {"path", p.path}});
  for (const auto& v : frame.pairs) {
    nlohmann::json j{{"pair", pairText(v.pair)}, {"verdict", consistencyName(v.verdict)}, {"cycle", v.cycle}};
    if (v.verdict != Consistency::Unchecked)
      j["cycle_error"] = {{"translation_m", v.cycle_translation}, {"yaw_deg", degrees(v.cycle_yaw)}};
    pairs.push_back(std::move(j));
  }
  return {{"reference", frame.reference},
          {"agents", poses},
          {"unreachable", frame.unreachable},
          {"pairs", pairs},
          {"optimised_pairs", frame.optimised_pairs},
          {"converged", frame.converged}};
}

}  // namespace tomomap
