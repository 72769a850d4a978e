#pragma once
// The matcher's settings a user may set: the daemon's `grid` and [match]
// table, and tomomap match's options, with one range each. The defaults are
// MatchParams' own (match_params.hpp).
#include <string>
#include <vector>

#include "match_params.hpp"
#include "setting.hpp"

namespace tomomap {

using MatchSetting = SettingOf<MatchParams>;

/// `grid` first, then the [match] keys in the reference's order.
const std::vector<MatchSetting>& matchSettings();

/// The one named `key` ("grid", "max_features", ...); std::logic_error if there is none.
const MatchSetting& matchSetting(const std::string& key);

}  // namespace tomomap
