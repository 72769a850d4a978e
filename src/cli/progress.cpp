#include "progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace tomomap::cli {

bool stderrIsTerminal() { return isatty(STDERR_FILENO) == 1; }

Progress terminalProgress(bool enabled) {
  if (!enabled) return {};
  return [](const char* stage, size_t done, size_t total) {
    std::fprintf(stderr, "\r%-12s %3zu%% (%zu/%zu)", stage, total ? done * 100 / total : 100, done, total);
    if (done >= total) std::fputc('\n', stderr);
    std::fflush(stderr);
  };
}

}  // namespace tomomap::cli
