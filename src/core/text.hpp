#pragma once
// Numbers as text for messages, logs and captions: every front end (the tool,
// its pictures, the daemon) prints fixed decimals the same way.
#include <iomanip>
#include <sstream>
#include <string>

namespace tomomap {

/// `v` with exactly `digits` decimals ("0.012", "42").
inline std::string fixed(double v, int digits) {
  std::ostringstream o;
  o << std::fixed << std::setprecision(digits) << v;
  return o.str();
}

}  // namespace tomomap
