// tomomapd: the per-robot daemon. Reads one config, describes the robot's map,
// exchanges tomographic features with the configured peers over DDS and keeps
// the agreed transforms in its output directory.
#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <thread>

#include "agent.hpp"
#include "config.hpp"
#include "core/types.hpp"
#include "log.hpp"
#include "settings.hpp"
#include "version.hpp"

using namespace tomomap::daemon;

int main(int argc, char** argv) {
  CLI::App app{"tomomapd " TOMOMAP_VERSION
               ": finds the transforms between this robot's map and its peers' maps, with no central node.\n"
               "Exit codes: 0 stopped cleanly, 2 bad config or map, 3 internal error.",
               "tomomapd"};
  app.set_version_flag("-V,--version", "tomomapd " TOMOMAP_VERSION);
  std::string config_path;
  bool check = false;
  auto* config_option =
      app.add_option("-c,--config", config_path, "config file (TOML; see docs/configuration.md); required");
  app.add_flag("--check", check, "check the config file, print the effective configuration and exit");
  bool reference = false;
  app.add_flag("--config-reference", reference,
               "print every config key (type, default, unit, range, what a reload does, meaning) as a Markdown "
               "table and exit");
  try {
    app.parse(argc, argv);
    if (!reference && config_option->empty()) throw CLI::RequiredError("--config");
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  if (reference) {
    std::cout << referenceTable();
    return 0;
  }

  Log log;
  Config config;
  try {
    config = loadConfig(config_path);
  } catch (const tomomap::InputError& e) {
    log.error(e.what());
    return 2;
  }
  log.setThreshold(config.log_level);
  if (config.faults.any())
    log.warning(std::string("test faults on (") + kTestFaultsVariable + "): " + config.faults.text() +
                "; never on a robot");
  if (check) {
    std::cout << describe(config) << "\n";
    // Not an error: at boot the map may come later, and the daemon waits for it.
    if (config.ros2.map_topic.empty() && !std::filesystem::exists(config.map))
      log.warning(config.map + " does not exist yet: tomomapd will wait for it");
    return 0;
  }

  // Signals are taken by one thread with sigwait: no work in a signal handler,
  // and every other thread (DDS's included) inherits the blocked mask.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  static Signals flags;  // outlives the detached thread
  std::thread([&signals, &log] {
    for (;;) {
      int sig = 0;
      if (sigwait(&signals, &sig) != 0) continue;
      if (sig == SIGHUP) {
        flags.reload = true;  // the agent's loop reloads
        continue;
      }
      log.info(std::string("received ") + (sig == SIGTERM ? "SIGTERM" : "SIGINT"));
      flags.stop = true;
      return;
    }
  }).detach();

  int code = 3;
  try {
    Agent agent(config, log);
    code = agent.run(flags);
    // A match still running on the worker is abandoned: leave without
    // unwinding it (results and state are already on disk, DDS is closed).
    std::fflush(nullptr);
    _exit(code);
  } catch (const std::exception& e) {
    log.error(std::string("internal error: ") + e.what());
  }
  return code;
}
