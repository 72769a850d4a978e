#include "match_settings.hpp"

#include "types.hpp"

namespace tomomap {
namespace {

std::vector<MatchSetting> declare() {
  using K = SettingKind;
  using M = MatchParams;
  using V = SettingValue;
  std::vector<MatchSetting> all;
  const auto add = [&](MatchSetting s, auto at) { all.push_back(std::move(bindField(s, at))); };
  // Kept in degrees, held in radians: read and written through the conversion.
  const auto addDegrees = [&](MatchSetting s, double M::*field) {
    s.get = [field](const M& m) -> V { return degrees(m.*field); };
    s.set = [field](M& m, const V& v) { m.*field = radians(std::get<double>(v)); };
    all.push_back(std::move(s));
  };
  add({"grid", K::Number, "m", 0.005, 10,
       "slice spacing and pixel size; the same on every agent (0.05 indoors, 0.2-0.5 outdoors)"},
      [](M& m) { return &m.grid; });
  // The wire's own bound (map_offer.cpp refuses an announcement asking for more).
  add({"max_features", K::Integer, "features", 1, 10000,
       "ORB keypoints kept per slice; announced with the map, so receivers run ORB the same way"},
      [](M& m) { return &m.features.max_features; });
  add({"fast_threshold", K::Integer, "", 1, 255,
       "FAST corner threshold on the 0/255 slice images; announced with the map"},
      [](M& m) { return &m.features.fast_threshold; });
  add({"ransac_threshold_cells", K::Number, "grid cells", 0.5, 50, "RANSAC inlier distance per slice pair"},
      [](M& m) { return &m.ransac_threshold_cells; });
  add({"ransac_iterations", K::Integer, "", 10, 100000, "RANSAC iterations per slice pair at most"},
      [](M& m) { return &m.ransac_iterations; });
  add({"ransac_confidence", K::Number, "", 0.5, 0.999999,
       "RANSAC stops once an all-inlier sample was drawn with this probability"},
      [](M& m) { return &m.ransac_confidence; });
  add({"min_matches", K::Integer, "", 2, 1000, "fewer mutual descriptor matches: the slice pair gives no estimate"},
      [](M& m) { return &m.min_matches; });
  add({"consensus_translation_cells", K::Number, "grid cells", 0.5, 100,
       "slice-pair estimates this close (and within the yaw below) agree"},
      [](M& m) { return &m.consensus_translation_cells; });
  addDegrees({"consensus_yaw_deg", K::Number, "degrees", 0.1, 90, "yaw tolerance of that agreement"},
             &M::consensus_yaw);
  add({"min_support", K::Integer, "slices", 1, 1000,
       "descriptive slices each map needs for the features to propose a pose; slices a dense search's best pose must "
       "hold over"},
      [](M& m) { return &m.min_support; });
  add({"threads", K::Integer, "", 0, 1024, "threads one match uses; 0 = every core"}, [](M& m) { return &m.threads; });
  addDegrees({"max_tilt_deg", K::Number, "degrees", 0, 90,
              "a map leaning more than this from gravity is levelled or refused (docs/algorithm.md, \"Gravity "
              "check\")"},
             &M::max_tilt);
  return all;
}

}  // namespace

const std::vector<MatchSetting>& matchSettings() {
  static const std::vector<MatchSetting> all = declare();
  return all;
}

const MatchSetting& matchSetting(const std::string& key) { return findSetting(matchSettings(), key); }

}  // namespace tomomap
