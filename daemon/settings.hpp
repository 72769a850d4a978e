#pragma once
// Every key of tomomapd's config file, declared once: its kind, unit, range,
// default, meaning and what a reload does when it changes. The reader
// (config.cpp), the effective configuration it logs (`--check`), the reload
// (agent_lifecycle.cpp) and docs/configuration.md's table
// (`tomomapd --config-reference`, checked by a test) are all driven from here.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "config.hpp"
#include "core/setting.hpp"

namespace tomomap::daemon {

/// What a changed value needs to take effect on `systemctl reload` (SIGHUP).
enum class Reload {
  AtOnce,        ///< applied as read (the map is read and described again)
  Rejoin,        ///< the agent leaves the network and joins again
  RestartsRos2,  ///< the ROS 2 node is made again
  Restart,       ///< refused on reload: restart the service
};

struct Setting : SettingOf<Config> {
  Reload reload = Reload::AtOnce;
  bool required = false;
  bool path = false;         ///< a file or folder, relative to the config file's folder
  std::string default_text;  ///< the reference's default where it is not a default Config's value
  /// Beyond kind and range: why a value is refused (nullopt: accepted).
  std::function<std::optional<std::string>(const SettingValue&)> check;
  /// The effective value `--check` shows where a default is resolved later (e.g. the lowest id of the fleet).
  std::function<std::string(const Config&)> shown;
  /// Set per element of an array of tables ([[peer]]): no field of Config of its own.
  bool perElement() const { return !get; }
  /// "match" of "match.threads"; empty for a top-level key.
  std::string table() const;
  /// "threads" of "match.threads".
  std::string name() const;
};

const std::vector<Setting>& settings();
/// The one named `key` ("discovery_port", "match.threads"); std::logic_error if there is none.
const Setting& setting(const std::string& key);
/// Whether `key` is declared (an unknown key in a config file is an error).
bool isSetting(const std::string& key);

/// The keys whose values differ between two configs and that need `reload` to take effect.
std::vector<std::string> changed(const Config& a, const Config& b, Reload reload);

/// docs/configuration.md's table of keys, as Markdown.
std::string referenceTable();

}  // namespace tomomap::daemon
