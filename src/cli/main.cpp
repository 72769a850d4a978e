// `tomomap`: offline map registration with tomographic features.
#include <vector>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include "commands.hpp"
#include "run_guarded.hpp"
#include "version.hpp"

using namespace tomomap::cli;

namespace {

/// A match allocates and frees the same large buffers stage after stage (a
/// map's cells, their landings, the correlation's images). glibc hands blocks
/// above its thresholds back to the kernel, and each was faulted in again, a
/// page at a time: on the slowest matrix pair 52 k page faults, 39 k kept
/// (docs/results.md, "Freed memory kept"). A one-shot process keeps what it
/// frees instead; its peak is unchanged. Blocks of more than 32 MB, glibc's
/// largest threshold, are still mapped alone.
void keepFreedMemory() {
#ifdef __GLIBC__
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
}

}  // namespace

int main(int argc, char** argv) {
  keepFreedMemory();
  CLI::App app{"tomomap " TOMOMAP_VERSION
               ": find the 4-DoF transform (x, y, z, yaw) between two gravity-aligned 3D maps.\n"
               "Exit codes: 0 success, 1 no reliable match, 2 bad input, 3 internal error.",
               "tomomap"};
  app.set_version_flag("-V,--version", "tomomap " TOMOMAP_VERSION);
  app.require_subcommand(1, 1);
  const std::vector<Command> commands{addMatchCommand(app), addSynthCommand(app),  addEvalCommand(app),
                                      addVizCommand(app),   addStatusCommand(app), addFleetKeysCommand(app),
                                      addMergeCommand(app)};
  return parseAndRun(app, argc, argv, [&] {
    for (const auto& c : commands)
      if (c.app->parsed()) return c.run();
    return kExitInternal;
  });
}
