#pragma once
// Small helpers the agent's source files share: clocks and pair names.
#include <chrono>
#include <cstdint>
#include <string>

#include "agent.hpp"
#include "core/text.hpp"

namespace tomomap::daemon::detail {

inline double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

inline uint64_t wallMs() {
  return static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::milliseconds>(
                                   std::chrono::system_clock::now().time_since_epoch())
                                   .count());
}

inline std::string pairText(const PairKey& p) { return p.first + "<-" + p.second; }

}  // namespace tomomap::daemon::detail
