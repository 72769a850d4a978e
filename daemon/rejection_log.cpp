#include "rejection_log.hpp"

#include <algorithm>

namespace tomomap::daemon {

std::optional<std::string> RejectionLog::note(const std::string& sender, const std::string& why,
                                              Clock::time_point now) {
  auto [it, first] = senders_.try_emplace(sender);
  Sender& s = it->second;
  if (first || (s.unlogged == 0 && now >= s.window_start + window_)) {
    s.window_start = now;
    return "rejected a sample from " + sender + ": " + why + " (more from " + sender + " are summarised once a minute)";
  }
  ++s.unlogged;
  // Bounded: a sender's reasons are the rejection texts, a few dozen kinds.
  if (s.reasons.size() < 64 || s.reasons.count(why)) ++s.reasons[why];
  return std::nullopt;
}

std::string RejectionLog::summary(const std::string& sender, const Sender& s) {
  const auto most = std::max_element(s.reasons.begin(), s.reasons.end(),
                                     [](const auto& a, const auto& b) { return a.second < b.second; });
  return "rejected " + std::to_string(s.unlogged) + " more samples from " + sender + " in the last minute" +
         (most != s.reasons.end() ? " (most often: " + most->first + ")" : "");
}

std::vector<std::string> RejectionLog::due(Clock::time_point now) {
  std::vector<std::string> lines;
  for (auto& [sender, s] : senders_) {
    if (s.unlogged == 0 || now < s.window_start + window_) continue;
    lines.push_back(summary(sender, s));
    s.unlogged = 0;
    s.reasons.clear();
    s.window_start = now;
  }
  return lines;
}

}  // namespace tomomap::daemon
