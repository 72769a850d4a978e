#include "match_settings.hpp"


#include "types.hpp"

namespace tomomap {
namespace {

double number(const SettingValue& v) { return std::get<double>(v); }
int whole(const SettingValue& v) { return static_cast<int>(std::get<double>(v)); }

std::vector<MatchSetting> declare() {
  using K = SettingKind;
  using M = MatchParams;
  using V = SettingValue;
  return {
      {"grid", K::Number, "m", 0.005, 10,
       "slice spacing and pixel size; the same on every agent (0.05 indoors, 0.2-0.5 outdoors)",
       [](const M& m) -> V { return m.grid; }, [](M& m, const V& v) { m.grid = number(v); }},
      // The wire's own bound (map_offer.cpp refuses an announcement asking for more).
      {"max_features", K::Integer, "features", 1, 10000,
       "ORB keypoints kept per slice; announced with the map, so receivers run ORB the same way",
       [](const M& m) -> V { return double(m.features.max_features); },
       [](M& m, const V& v) { m.features.max_features = whole(v); }},
      {"fast_threshold", K::Integer, "", 1, 255,
       "FAST corner threshold on the 0/255 slice images; announced with the map",
       [](const M& m) -> V { return double(m.features.fast_threshold); },
       [](M& m, const V& v) { m.features.fast_threshold = whole(v); }},
      {"ransac_threshold_cells", K::Number, "grid cells", 0.5, 50, "RANSAC inlier distance per slice pair",
       [](const M& m) -> V { return m.ransac_threshold_cells; },
       [](M& m, const V& v) { m.ransac_threshold_cells = number(v); }},
      {"ransac_iterations", K::Integer, "", 10, 100000, "RANSAC iterations per slice pair at most",
       [](const M& m) -> V { return double(m.ransac_iterations); },
       [](M& m, const V& v) { m.ransac_iterations = whole(v); }},
      {"ransac_confidence", K::Number, "", 0.5, 0.999999,
       "RANSAC stops once an all-inlier sample was drawn with this probability",
       [](const M& m) -> V { return m.ransac_confidence; }, [](M& m, const V& v) { m.ransac_confidence = number(v); }},
      {"min_matches", K::Integer, "", 2, 1000, "fewer mutual descriptor matches: the slice pair gives no estimate",
       [](const M& m) -> V { return double(m.min_matches); }, [](M& m, const V& v) { m.min_matches = whole(v); }},
      {"consensus_translation_cells", K::Number, "grid cells", 0.5, 100,
       "slice-pair estimates this close (and within the yaw below) agree",
       [](const M& m) -> V { return m.consensus_translation_cells; },
       [](M& m, const V& v) { m.consensus_translation_cells = number(v); }},
      {"consensus_yaw_deg", K::Number, "degrees", 0.1, 90, "yaw tolerance of that agreement",
       [](const M& m) -> V { return degrees(m.consensus_yaw); },
       [](M& m, const V& v) { m.consensus_yaw = radians(number(v)); }},
      {"min_support", K::Integer, "slice pairs", 1, 1000, "fewer agreeing slice pairs: no reliable match",
       [](const M& m) -> V { return double(m.min_support); }, [](M& m, const V& v) { m.min_support = whole(v); }},
      {"min_inliers", K::Integer, "", 2, 100000, "fewer inlier correspondences: no reliable match",
       [](const M& m) -> V { return double(m.min_inliers); }, [](M& m, const V& v) { m.min_inliers = whole(v); }},
      {"threads", K::Integer, "", 0, 1024, "threads one match uses; 0 = every core",
       [](const M& m) -> V { return double(m.threads); }, [](M& m, const V& v) { m.threads = whole(v); }},
      {"max_tilt_deg", K::Number, "degrees", 0, 90,
       "a map leaning more than this from gravity is levelled or refused (docs/algorithm.md, \"Gravity check\")",
       [](const M& m) -> V { return degrees(m.max_tilt); }, [](M& m, const V& v) { m.max_tilt = radians(number(v)); }},
  };
}

}  // namespace

const std::vector<MatchSetting>& matchSettings() {
  static const std::vector<MatchSetting> all = declare();
  return all;
}

const MatchSetting& matchSetting(const std::string& key) { return findSetting(matchSettings(), key); }

}  // namespace tomomap
