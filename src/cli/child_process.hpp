#pragma once
// Runs a program as a child process and measures it: wall time and peak RSS of
// that process alone (wait4's rusage), so one method's memory never hides another's.
#include <string>
#include <vector>

namespace tomomap::cli {

struct ChildRun {
  int exit_code = -1;      ///< -1 if it did not exit normally (signal)
  double seconds = 0;      ///< wall time
  double cpu_seconds = 0;  ///< user and system time of all its threads
  double peak_rss_mb = 0;  ///< maximum resident set size
  std::string output;      ///< stdout and stderr together
  bool timed_out = false;  ///< killed after the time limit
};

/// `timeout_s` > 0: the child is killed (SIGKILL) once it has run that long.
ChildRun runChild(const std::vector<std::string>& argv, double timeout_s = 0);

/// Absolute path of a binary installed beside the running one.
std::string siblingBinary(const std::string& name);

/// Absolute path of the running binary itself: a copy of it under another
/// name (a build being compared with another) runs its own matches.
std::string selfBinary();

}  // namespace tomomap::cli
