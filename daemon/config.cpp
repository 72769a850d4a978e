#include "config.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <set>
#include <sstream>

#include "core/types.hpp"
#include "settings.hpp"

namespace tomomap::daemon {
namespace {

namespace fs = std::filesystem;

struct Reader {
  std::string file;

  [[noreturn]] void fail(const toml::node& n, const std::string& key, const std::string& what) const {
    const auto& b = n.source().begin;
    throw InputError(file + ":" + std::to_string(b.line) + ":" + std::to_string(b.column) + ": key '" + key +
                     "': " + what);
  }
  [[noreturn]] void missing(const toml::table& t, const std::string& key) const {
    const auto& b = t.source().begin;
    throw InputError(file + ":" + std::to_string(b.line) + ":" + std::to_string(b.column) + ": key '" + key +
                     "' is required");
  }
};

/// The optional table `[name]`, every key of it a setting; null if absent.
const toml::table* knownTable(const Reader& r, const toml::table& root, const std::string& name) {
  const toml::node* node = root.get(name);
  if (!node) return nullptr;
  const toml::table* t = node->as_table();
  if (!t) r.fail(*node, name, "must be a table ([" + name + "])");
  for (const auto& [key, value] : *t) {
    const std::string full = name + "." + std::string(key.str());
    if (!isSetting(full)) r.fail(value, full, "unknown key (see docs/configuration.md)");
  }
  return t;
}

/// Reads one setting's node as its kind asks, in its range, passing its check.
SettingValue valueOf(const Reader& r, const Setting& s, const toml::node& n,
                     const std::function<std::string(const std::string&)>& resolve) {
  const std::string key = s.key;
  SettingValue v;
  switch (s.kind) {
    case SettingKind::Flag:
      if (!n.is_boolean()) r.fail(n, key, "must be true or false");
      v = n.value<bool>().value();
      break;
    case SettingKind::Integer:
    case SettingKind::Number: {
      const auto d = n.value<double>();
      if (!d || !s.inRange(*d) || !n.is_number())
        r.fail(n, key, "must be a number from " + settingText(s.lo) + " to " + settingText(s.hi));
      if (s.kind == SettingKind::Integer && *d != std::floor(*d)) r.fail(n, key, "must be a whole number");
      v = *d;
      break;
    }
    case SettingKind::Text:
      if (!n.is_string()) r.fail(n, key, "must be a string");
      v = s.path ? resolve(n.value<std::string>().value()) : n.value<std::string>().value();
      break;
  }
  if (s.check)
    if (const auto why = s.check(v)) r.fail(n, key, *why);
  return v;
}

/// Every setting with a field of its own, from its table (absent: the default stays).
void readSettings(const Reader& r, const toml::table& root,
                  const std::function<std::string(const std::string&)>& resolve, Config& c) {
  for (const Setting& s : settings()) {
    if (s.perElement()) continue;
    const std::string t = s.table();
    const toml::table* table = t.empty() ? &root : knownTable(r, root, t);
    if (!table) continue;
    const toml::node* n = table->get(s.name());
    if (!n) {
      if (s.required) r.missing(*table, s.key);
      continue;
    }
    s.set(c, valueOf(r, s, *n, resolve));
  }
}

/// The [[peer]] tables: their keys are settings set per element.
void readPeers(const Reader& r, const toml::table& root, transport::TransportConfig& t) {
  const toml::node* peers = root.get("peer");
  if (!peers) return;
  const toml::array* a = peers->as_array();
  if (!a) r.fail(*peers, "peer", "must be an array of tables ([[peer]])");
  std::set<std::string> ids{t.agent};
  const auto none = [](const std::string& p) { return p; };
  for (const auto& e : *a) {
    const toml::table* p = e.as_table();
    if (!p) r.fail(e, "peer", "each [[peer]] must be a table");
    for (const auto& [key, node] : *p) {
      const std::string full = "peer." + std::string(key.str());
      if (!isSetting(full)) r.fail(node, full, "unknown key (use id, host, port)");
    }
    const auto read = [&](const char* key) {
      const Setting& s = setting(std::string("peer.") + key);
      const toml::node* n = p->get(key);
      if (!n) r.missing(*p, s.key);
      return valueOf(r, s, *n, none);
    };
    transport::PeerAddress pa;
    pa.id = std::get<std::string>(read("id"));
    if (!ids.insert(pa.id).second)
      r.fail(*p->get("id"), "peer.id", "'" + pa.id + "' is listed twice or is this agent's own id");
    pa.host = std::get<std::string>(read("host"));
    pa.port = static_cast<uint16_t>(std::get<double>(read("port")));
    t.peers.push_back(pa);
  }
}

/// The [security] table: all its files but `crl` are required with it, and a
/// digest of their contents is kept (a reload that finds a renewed file joins again).
void checkSecurity(const Reader& r, const toml::table& root, transport::SecurityFiles& f) {
  const toml::table* t = knownTable(r, root, "security");
  if (!t) return;
  for (const char* key : {"ca", "certificate", "private_key", "governance", "permissions"})
    if (!t->get(key)) r.missing(*t, std::string("security.") + key);
  std::string all;
  for (const auto& path : {f.ca, f.certificate, f.private_key, f.governance, f.permissions, f.crl}) {
    std::ifstream in(path);
    all += std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()) + '\0';
  }
  f.contents = std::hash<std::string>{}(all);
}

/// What the settings cannot say alone: defaults from other keys, keys that
/// name fleet members, and where the map comes from.
void checkTogether(const Reader& r, const toml::table& root,
                   const std::function<std::string(const std::string&)>& resolve, Config& c) {
  auto& t = c.transport;
  if (!root.get("data_port")) t.data_port = static_cast<uint16_t>(t.discovery_port + 1);
  if (t.data_port == t.discovery_port) r.fail(*root.get("data_port"), "data_port", "must differ from discovery_port");
  // Under systemd, StateDirectory= names the place (STATE_DIRECTORY).
  if (!root.get("output_dir")) {
    const char* state_dir = std::getenv("STATE_DIRECTORY");
    c.output_dir = resolve(state_dir && *state_dir ? state_dir : "/var/lib/tomomap");
  }
  if (!c.reference.empty() && !c.inFleet(c.reference))
    r.fail(*root.get("reference"), "reference", "'" + c.reference + "' is neither this agent nor one of its peers");
  if (const toml::table* ros = root.get("ros2") ? root.get("ros2")->as_table() : nullptr) {
    // The table turns ROS 2 on unless it says `enabled = false`.
    if (!ros->get("enabled")) c.ros2.enabled = true;
    if (!c.ros2.root.empty() && !c.inFleet(c.ros2.root))
      r.fail(*ros->get("root"), "ros2.root", "'" + c.ros2.root + "' is neither this agent nor one of its peers");
    std::vector<std::string> fleet = c.peerIds();
    fleet.push_back(c.agent());
    for (const auto& agent : fleet)  // a frame cannot hang from itself
      if (!c.ros2.world.empty() && c.ros2.frameOf(agent) == c.ros2.world)
        r.fail(*ros->get("world"), "ros2.world", "'" + c.ros2.world + "' is " + agent + "'s map frame");
    if (!c.ros2.map_topic.empty()) {
      if (!c.ros2.enabled) r.fail(*ros->get("map_topic"), "ros2.map_topic", "needs [ros2] enabled");
      if (!c.map.empty())
        r.fail(*ros->get("map_topic"), "ros2.map_topic", "the map comes from one place: remove `map` or `map_topic`");
    }
  }
  if (c.map.empty() && c.ros2.map_topic.empty()) r.missing(root, "map");
  if (!c.fleet_map.band.valid()) {
    const toml::node* table = root.get("fleet_map");
    const toml::node* at = table && table->as_table() ? table->as_table()->get("band_high") : nullptr;
    r.fail(at ? *at : table ? *table : static_cast<const toml::node&>(root), "fleet_map.band_high", "must be above band_low");
  }
}

}  // namespace

bool Config::isPeer(const std::string& id) const {
  for (const auto& p : transport.peers)
    if (p.id == id) return true;
  return false;
}

std::vector<std::string> Config::peerIds() const {
  std::vector<std::string> ids;
  for (const auto& p : transport.peers) ids.push_back(p.id);
  return ids;
}

std::string Config::frameReference() const {
  if (!reference.empty()) return reference;
  std::string lowest = agent();
  for (const auto& p : transport.peers) lowest = std::min(lowest, p.id);
  return lowest;
}

std::string Config::treeRoot() const { return ros2.root.empty() ? frameReference() : ros2.root; }

std::string mapTypeName(transport::MapMessageType type) {
  std::string name = transport::rosTypeName(type);
  return name.erase(name.find("/msg/"), 4);
}

std::string Ros2Config::frameOf(const std::string& agent) const {
  std::string f = frame;
  for (size_t at = f.find("{agent}"); at != std::string::npos; at = f.find("{agent}", at + agent.size()))
    f.replace(at, 7, agent);
  return f;
}

Config loadConfig(const std::string& path) {
  if (!fs::exists(path)) throw InputError(path + ": no such config file");
  toml::table root;
  try {
    root = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    throw InputError(path + ":" + std::to_string(b.line) + ":" + std::to_string(b.column) + ": " +
                     std::string(e.description()));
  }
  const Reader r{path};
  const fs::path base = fs::absolute(path).parent_path();
  auto resolve = [&](const std::string& p) { return (base / p).lexically_normal().string(); };
  for (const auto& [key, node] : root) {
    const std::string k(key.str());
    const auto& all = settings();
    const bool known = k == "peer" || std::any_of(all.begin(), all.end(),
                                                  [&](const Setting& s) { return s.key == k || s.table() == k; });
    if (!known) r.fail(node, k, "unknown key (see docs/configuration.md)");
  }

  Config c;
  c.file = fs::absolute(path).lexically_normal().string();
  readSettings(r, root, resolve, c);
  readPeers(r, root, c.transport);
  checkSecurity(r, root, c.transport.security);
  checkTogether(r, root, resolve, c);
  c.faults = testFaultsFromEnvironment();
  c.transport.test_drop_percent = c.faults.drop_percent;
  return c;
}

std::string describe(const Config& c) {
  std::ostringstream o;
  o << "config " << c.file;
  for (const Setting& s : settings()) {
    if (s.perElement()) continue;
    const std::string t = s.table();
    if ((t == "security" && !c.transport.security.enabled()) || (t == "ros2" && !c.ros2.enabled)) continue;
    o << "\n  " << s.key << " = " << (s.shown ? s.shown(c) : settingText(s.get(c)));
  }
  if (!c.transport.security.enabled()) o << "\n  security: off (no [security] table)";
  if (!c.ros2.enabled) o << "\n  ros2: off (no [ros2] table)";
  if (c.faults.any()) o << "\n  test faults (" << kTestFaultsVariable << ") = " << c.faults.text();
  for (const auto& p : c.transport.peers) o << "\n  peer " << p.id << " = " << p.host << ":" << p.port;
  return o.str();
}

}  // namespace tomomap::daemon
