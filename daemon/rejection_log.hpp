#pragma once
// Log lines for rejected samples, bounded: a peer (or a forger naming one) can
// send thousands of bad samples a second, and one warning line each flooded
// the journal (about 4,500 lines per daemon in a fuzz run). The first
// rejection from a sender is logged at once; the rest are counted and
// summarised once per window.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "clock.hpp"

namespace tomomap::daemon {

class RejectionLog {
 public:
  explicit RejectionLog(Clock::duration window = std::chrono::minutes(1)) : window_(window) {}

  /// A sample from `sender` was rejected for `why`: the line to log now, if any.
  std::optional<std::string> note(const std::string& sender, const std::string& why, Clock::time_point now);
  /// Summaries for senders whose window has ended with rejections not yet logged.
  std::vector<std::string> due(Clock::time_point now);

 private:
  struct Sender {
    Clock::time_point window_start{};
    size_t unlogged = 0;
    std::map<std::string, size_t> reasons;  ///< of the unlogged ones
  };
  static std::string summary(const std::string& sender, const Sender& s);

  Clock::duration window_;
  std::map<std::string, Sender> senders_;
};

}  // namespace tomomap::daemon
