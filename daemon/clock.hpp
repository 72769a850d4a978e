#pragma once
// The daemon's two clocks: steady time for intervals, wall time for what is
// stored and shown.
#include <chrono>
#include <cstdint>

namespace tomomap::daemon {

using Clock = std::chrono::steady_clock;

inline double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

inline Clock::duration fromSeconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

inline uint64_t wallMs() {
  return static_cast<uint64_t>(
      std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count());
}

}  // namespace tomomap::daemon
