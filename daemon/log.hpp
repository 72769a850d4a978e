#pragma once
// Log lines to stderr: with syslog priority prefixes ("<6>") when journald
// reads them (JOURNAL_STREAM is set), with a UTC time and level otherwise.
#include <atomic>
#include <sstream>
#include <string>

#include "config.hpp"

namespace tomomap::daemon {

class Log {
 public:
  explicit Log(LogLevel threshold = LogLevel::Info);
  void setThreshold(LogLevel l) { threshold_ = l; }
  void write(LogLevel level, const std::string& line) const;
  void debug(const std::string& l) const { write(LogLevel::Debug, l); }
  void info(const std::string& l) const { write(LogLevel::Info, l); }
  void warning(const std::string& l) const { write(LogLevel::Warning, l); }
  void error(const std::string& l) const { write(LogLevel::Error, l); }

 private:
  std::atomic<LogLevel> threshold_;  ///< changed by a reload while other threads log
  bool journald_;
};

}  // namespace tomomap::daemon
