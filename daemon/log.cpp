#include "log.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <mutex>

namespace tomomap::daemon {

Log::Log(LogLevel threshold) : threshold_(threshold), journald_(std::getenv("JOURNAL_STREAM") != nullptr) {}

void Log::write(LogLevel level, const std::string& line) const {
  if (level < threshold_) return;
  static std::mutex mutex;
  static const char* names[] = {"debug", "info", "warning", "error"};
  static const int priorities[] = {7, 6, 4, 3};  // syslog: debug, info, warning, err
  std::string out;
  if (journald_) {
    out = "<" + std::to_string(priorities[static_cast<int>(level)]) + ">" + line + "\n";
  } else {
    const auto now = std::chrono::system_clock::now();
    const std::time_t t = std::chrono::system_clock::to_time_t(now);
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
    std::tm tm{};
    gmtime_r(&t, &tm);
    char stamp[32];
    std::snprintf(stamp, sizeof stamp, "%02d:%02d:%02d.%03d", tm.tm_hour, tm.tm_min, tm.tm_sec, static_cast<int>(ms));
    out = std::string(stamp) + " " + names[static_cast<int>(level)] + ": " + line + "\n";
  }
  std::lock_guard<std::mutex> lock(mutex);
  std::fputs(out.c_str(), stderr);
  std::fflush(stderr);
}

}  // namespace tomomap::daemon
