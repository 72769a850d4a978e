#pragma once
// Faults a test injects into a running daemon: named in the environment
// variable TOMOMAPD_TEST_FAULTS, never in the config file, so that no
// installed robot's configuration can switch one on by mistake
// (docs/operations.md, "Testing").
#include <string>

namespace tomomap::daemon {

constexpr const char* kTestFaultsVariable = "TOMOMAPD_TEST_FAULTS";

struct TestFaults {
  /// Share of the RTPS messages this agent sends that Fast DDS's lossy test
  /// transport drops [%], 0-90: loss on a link without netem.
  int drop_percent = 0;
  /// "target<-source": when this agent computes that pair, it publishes the
  /// result moved 1.5 m and 30 deg (a wrong match on demand, for the cycle checks).
  std::string wrong_pair;

  bool any() const { return drop_percent > 0 || !wrong_pair.empty(); }
  /// "drop_percent=10,wrong_pair=bravo<-delta" (the parts set).
  std::string text() const;
};

/// Reads "key=value" items separated by commas (drop_percent, wrong_pair).
/// Throws InputError naming the variable for anything else.
TestFaults parseTestFaults(const std::string& text);

/// The faults TOMOMAPD_TEST_FAULTS names; none when it is unset or empty.
TestFaults testFaultsFromEnvironment();

}  // namespace tomomap::daemon
