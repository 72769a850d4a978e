#include "test_faults.hpp"

#include <cstdlib>
#include <sstream>

#include "core/types.hpp"

namespace tomomap::daemon {

std::string TestFaults::text() const {
  std::string s;
  if (drop_percent > 0) s += "drop_percent=" + std::to_string(drop_percent);
  if (!wrong_pair.empty()) s += std::string(s.empty() ? "" : ",") + "wrong_pair=" + wrong_pair;
  return s;
}

TestFaults parseTestFaults(const std::string& text) {
  TestFaults f;
  std::istringstream items(text);
  const auto bad = [&](const std::string& why) {
    return InputError(std::string(kTestFaultsVariable) + "='" + text + "': " + why +
                      " (use drop_percent=0-90 and wrong_pair=target<-source, separated by commas)");
  };
  for (std::string item; std::getline(items, item, ',');) {
    if (item.empty()) continue;
    const size_t eq = item.find('=');
    if (eq == std::string::npos) throw bad("'" + item + "' is not key=value");
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    if (key == "drop_percent") {
      char* end = nullptr;
      const long v = std::strtol(value.c_str(), &end, 10);
      if (value.empty() || *end != '\0' || v < 0 || v > 90) throw bad("drop_percent must be 0-90");
      f.drop_percent = static_cast<int>(v);
    } else if (key == "wrong_pair") {
      if (value.find("<-") == std::string::npos) throw bad("wrong_pair must read target<-source");
      f.wrong_pair = value;
    } else {
      throw bad("unknown fault '" + key + "'");
    }
  }
  return f;
}

TestFaults testFaultsFromEnvironment() {
  const char* v = std::getenv(kTestFaultsVariable);
  return v ? parseTestFaults(v) : TestFaults{};
}

}  // namespace tomomap::daemon
