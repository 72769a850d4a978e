#include "config.hpp"

#include <toml++/toml.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <regex>
#include <set>
#include <sstream>

#include "core/types.hpp"

namespace tomomap::daemon {
namespace {

namespace fs = std::filesystem;

const std::vector<std::string> kKeys{"agent",
                                     "map",
                                     "grid",
                                     "domain",
                                     "address",
                                     "discovery_port",
                                     "data_port",
                                     "bandwidth_kbps",
                                     "output_dir",
                                     "log_level",
                                     "claim_timeout_s",
                                     "request_interval_s",
                                     "peer_memory_mb",
                                     "reference",
                                     "peer.id",
                                     "peer.host",
                                     "peer.port",
                                     "match.max_features",
                                     "match.fast_threshold",
                                     "match.ransac_threshold_cells",
                                     "match.ransac_iterations",
                                     "match.ransac_confidence",
                                     "match.min_matches",
                                     "match.consensus_translation_cells",
                                     "match.consensus_yaw_deg",
                                     "match.min_support",
                                     "match.min_inliers",
                                     "match.threads",
                                     "match.max_tilt_deg",
                                     "security.ca",
                                     "security.certificate",
                                     "security.private_key",
                                     "security.governance",
                                     "security.permissions",
                                     "security.crl",
                                     "ros2.enabled",
                                     "ros2.domain",
                                     "ros2.frame",
                                     "ros2.root",
                                     "ros2.localhost_only",
                                     "ros2.map_topic"};

struct Reader {
  std::string file;

  [[noreturn]] void fail(const toml::node& n, const std::string& key, const std::string& what) const {
    const auto& b = n.source().begin;
    throw InputError(file + ":" + std::to_string(b.line) + ":" + std::to_string(b.column) + ": key '" + key +
                     "': " + what);
  }
  /// An integer key: a number from lo to hi with no fraction.
  int integer(const toml::table& t, const std::string& key, int fallback, int lo, int hi) const {
    const double v = number(t, key, fallback, lo, hi);
    if (v != static_cast<int>(v)) fail(*t.get(key), key, "must be a whole number");
    return static_cast<int>(v);
  }

  [[noreturn]] void missing(const toml::table& t, const std::string& key) const {
    const auto& b = t.source().begin;
    throw InputError(file + ":" + std::to_string(b.line) + ":" + std::to_string(b.column) + ": key '" + key +
                     "' is required");
  }

  std::string text(const toml::table& t, const std::string& key, const std::optional<std::string>& fallback) const {
    const toml::node* n = t.get(key);
    if (!n) {
      if (fallback) return *fallback;
      missing(t, key);
    }
    if (!n->is_string()) fail(*n, key, "must be a string");
    return n->value<std::string>().value();
  }

  double number(const toml::table& t, const std::string& key, std::optional<double> fallback, double lo,
                double hi) const {
    const toml::node* n = t.get(key);
    if (!n) {
      if (fallback) return *fallback;
      missing(t, key);
    }
    const auto v = n->value<double>();
    if (!v || !(*v >= lo && *v <= hi)) fail(*n, key, "must be a number from " + toString(lo) + " to " + toString(hi));
    return *v;
  }

  bool flag(const toml::table& t, const std::string& key, bool fallback) const {
    const toml::node* n = t.get(key);
    if (!n) return fallback;
    if (!n->is_boolean()) fail(*n, key, "must be true or false");
    return n->value<bool>().value();
  }

  static std::string toString(double v) {
    std::ostringstream o;
    o << v;
    return o.str();
  }
};

std::string checkedId(const Reader& r, const toml::table& t, const std::string& key) {
  const std::string id = r.text(t, key, std::nullopt);
  if (!std::regex_match(id, std::regex("[A-Za-z0-9_-]{1,32}")))
    r.fail(*t.get(key), key, "must be 1 to 32 letters, digits, '-' or '_'");
  return id;
}

/// The optional table `[name]`, every key of it one of kKeys; null if absent.
const toml::table* knownTable(const Reader& r, const toml::table& root, const std::string& name) {
  const toml::node* node = root.get(name);
  if (!node) return nullptr;
  const toml::table* t = node->as_table();
  if (!t) r.fail(*node, name, "must be a table ([" + name + "])");
  for (const auto& [key, value] : *t)
    if (std::find(kKeys.begin(), kKeys.end(), name + "." + std::string(key.str())) == kKeys.end())
      r.fail(value, name + "." + std::string(key.str()), "unknown key (see docs/configuration.md)");
  return t;
}

/// The [match] table: each key overrides one MatchParams field; absent keys
/// keep the matcher's own defaults.
void readMatch(const Reader& r, const toml::table& root, MatchParams& m) {
  const toml::table* t = knownTable(r, root, "match");
  if (!t) return;
  m.features.max_features = r.integer(*t, "max_features", m.features.max_features, 1, 10000);
  m.features.fast_threshold = r.integer(*t, "fast_threshold", m.features.fast_threshold, 1, 255);
  m.ransac_threshold_cells = r.number(*t, "ransac_threshold_cells", m.ransac_threshold_cells, 0.5, 50);
  m.ransac_iterations = r.integer(*t, "ransac_iterations", m.ransac_iterations, 10, 100000);
  m.ransac_confidence = r.number(*t, "ransac_confidence", m.ransac_confidence, 0.5, 0.999999);
  m.min_matches = r.integer(*t, "min_matches", m.min_matches, 2, 1000);
  m.consensus_translation_cells = r.number(*t, "consensus_translation_cells", m.consensus_translation_cells, 0.5, 100);
  m.consensus_yaw = radians(r.number(*t, "consensus_yaw_deg", degrees(m.consensus_yaw), 0.1, 90));
  m.min_support = r.integer(*t, "min_support", m.min_support, 1, 1000);
  m.min_inliers = r.integer(*t, "min_inliers", m.min_inliers, 2, 100000);
  m.threads = r.integer(*t, "threads", m.threads, 0, 256);
  m.max_tilt = radians(r.number(*t, "max_tilt_deg", degrees(m.max_tilt), 0, 90));
}

/// A ROS 2 topic name: segments of letters, digits and _, not starting with a
/// digit, separated by / (a leading / or none: relative names resolve to the root).
bool validRosTopic(const std::string& name) {
  std::string rest = name.rfind('/', 0) == 0 ? name.substr(1) : name;
  if (rest.empty() || rest.back() == '/') return false;
  bool segment_start = true;
  for (char ch : rest) {
    if (ch == '/') {
      if (segment_start) return false;  // an empty segment
      segment_start = true;
      continue;
    }
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_')) return false;
    if (segment_start && std::isdigit(static_cast<unsigned char>(ch))) return false;
    segment_start = false;
  }
  return true;
}

/// The [ros2] table: present means on, unless it says `enabled = false`.
void readRos2(const Reader& r, const toml::table& root, Config& c) {
  const toml::table* t = knownTable(r, root, "ros2");
  if (!t) return;
  Ros2Config& ros = c.ros2;
  ros.enabled = r.flag(*t, "enabled", true);
  ros.domain = r.integer(*t, "domain", ros.domain, 0, 232);
  ros.frame = r.text(*t, "frame", ros.frame);
  if (ros.frame.find("{agent}") == std::string::npos)
    r.fail(*t->get("frame"), "ros2.frame", "must contain {agent} (each map needs its own frame)");
  ros.root = r.text(*t, "root", std::string());
  if (!ros.root.empty() && !c.inFleet(ros.root))
    r.fail(*t->get("root"), "ros2.root", "'" + ros.root + "' is neither this agent nor one of its peers");
  ros.localhost_only = r.flag(*t, "localhost_only", ros.localhost_only);
  ros.map_topic = r.text(*t, "map_topic", std::string());
  if (!ros.map_topic.empty()) {
    if (!ros.enabled) r.fail(*t->get("map_topic"), "ros2.map_topic", "needs [ros2] enabled");
    if (!c.map.empty())
      r.fail(*t->get("map_topic"), "ros2.map_topic", "the map comes from one place: remove `map` or `map_topic`");
    if (!validRosTopic(ros.map_topic))
      r.fail(*t->get("map_topic"), "ros2.map_topic",
             "'" + ros.map_topic + "' is not a ROS 2 topic name (letters, digits, _ and / only, e.g. /Laser_map)");
  }
}

/// The [security] table: DDS Security's files, each of which must exist
/// (relative paths from the config's folder). All but `crl` are required.
void readSecurity(const Reader& r, const toml::table& root,
                  const std::function<std::string(const std::string&)>& resolve, transport::SecurityFiles& f) {
  const toml::table* t = knownTable(r, root, "security");
  if (!t) return;
  auto file = [&](const std::string& key, bool required) -> std::string {
    if (!required && !t->get(key)) return "";
    const std::string path = resolve(r.text(*t, key, std::nullopt));
    if (!fs::is_regular_file(path))
      r.fail(*t->get(key), "security." + key, "no such file: " + path + " (tomomap fleet-keys makes them)");
    return path;
  };
  f.ca = file("ca", true);
  f.certificate = file("certificate", true);
  f.private_key = file("private_key", true);
  f.governance = file("governance", true);
  f.permissions = file("permissions", true);
  f.crl = file("crl", false);
  std::string all;
  for (const auto& path : {f.ca, f.certificate, f.private_key, f.governance, f.permissions, f.crl}) {
    std::ifstream in(path);
    all += std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()) + '\0';
  }
  f.contents = std::hash<std::string>{}(all);
}

std::string checkedAddress(const Reader& r, const toml::table& t, const std::string& key,
                           const std::optional<std::string>& fallback) {
  const std::string a = r.text(t, key, fallback);
  if (!std::regex_match(a, std::regex(R"((\d{1,3})\.(\d{1,3})\.(\d{1,3})\.(\d{1,3}))")))
    r.fail(*t.get(key), key, "must be an IPv4 address such as 192.168.1.20");
  return a;
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

std::string Ros2Config::frameOf(const std::string& agent) const {
  std::string f = frame;
  for (size_t at = f.find("{agent}"); at != std::string::npos; at = f.find("{agent}", at + agent.size()))
    f.replace(at, 7, agent);
  return f;
}

const std::vector<std::string>& configKeys() { return kKeys; }

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
    if (k != "peer" && k != "match" && k != "security" && k != "ros2" &&
        std::find(kKeys.begin(), kKeys.end(), k) == kKeys.end())
      r.fail(node, k, "unknown key (see docs/configuration.md)");
  }

  Config c;
  c.file = fs::absolute(path).lexically_normal().string();
  auto& t = c.transport;
  t.agent = checkedId(r, root, "agent");
  // Required unless [ros2] map_topic brings the map (checked after it).
  if (root.get("map")) c.map = resolve(r.text(root, "map", std::nullopt));
  c.match.grid = r.number(root, "grid", c.match.grid, 0.005, 10);
  readMatch(r, root, c.match);
  t.domain = static_cast<int>(r.number(root, "domain", 0, 0, 232));
  t.address = checkedAddress(r, root, "address", "127.0.0.1");
  t.discovery_port = static_cast<uint16_t>(r.number(root, "discovery_port", std::nullopt, 1024, 65534));
  t.data_port = static_cast<uint16_t>(r.number(root, "data_port", t.discovery_port + 1.0, 1024, 65535));
  if (t.data_port == t.discovery_port) r.fail(*root.get("data_port"), "data_port", "must differ from discovery_port");
  t.bandwidth_kbps = r.number(root, "bandwidth_kbps", 10000, 64, 10'000'000);
  // Under systemd, StateDirectory= names the place (STATE_DIRECTORY).
  const char* state_dir = std::getenv("STATE_DIRECTORY");
  c.output_dir = resolve(r.text(root, "output_dir", state_dir && *state_dir ? state_dir : "/var/lib/tomomap"));
  const std::string level = r.text(root, "log_level", "info");
  if (level == "debug")
    c.log_level = LogLevel::Debug;
  else if (level == "info")
    c.log_level = LogLevel::Info;
  else if (level == "warning")
    c.log_level = LogLevel::Warning;
  else if (level == "error")
    c.log_level = LogLevel::Error;
  else
    r.fail(*root.get("log_level"), "log_level", "must be debug, info, warning or error");
  c.claim_timeout_s = r.number(root, "claim_timeout_s", 30, 1, 3600);
  c.request_interval_s = r.number(root, "request_interval_s", 1, 0.1, 600);
  c.peer_memory_mb = r.number(root, "peer_memory_mb", c.peer_memory_mb, 1, 65536);
  c.faults = testFaultsFromEnvironment();
  t.test_drop_percent = c.faults.drop_percent;
  readSecurity(r, root, resolve, t.security);

  if (const toml::node* peers = root.get("peer")) {
    const toml::array* a = peers->as_array();
    if (!a) r.fail(*peers, "peer", "must be an array of tables ([[peer]])");
    std::set<std::string> ids{t.agent};
    for (const auto& e : *a) {
      const toml::table* p = e.as_table();
      if (!p) r.fail(e, "peer", "each [[peer]] must be a table");
      for (const auto& [key, node] : *p) {
        const std::string k(key.str());
        if (k != "id" && k != "host" && k != "port") r.fail(node, "peer." + k, "unknown key (use id, host, port)");
      }
      transport::PeerAddress pa;
      pa.id = checkedId(r, *p, "id");
      if (!ids.insert(pa.id).second)
        r.fail(*p->get("id"), "peer.id", "'" + pa.id + "' is listed twice or is this agent's own id");
      pa.host = checkedAddress(r, *p, "host", std::nullopt);
      pa.port = static_cast<uint16_t>(r.number(*p, "port", std::nullopt, 1024, 65534));
      t.peers.push_back(pa);
    }
  }
  // After the peers: the reference must be one of the fleet.
  c.reference = r.text(root, "reference", std::string());
  if (!c.reference.empty() && !c.inFleet(c.reference))
    r.fail(*root.get("reference"), "reference", "'" + c.reference + "' is neither this agent nor one of its peers");
  readRos2(r, root, c);
  if (c.map.empty() && c.ros2.map_topic.empty()) r.missing(root, "map");
  return c;
}

std::string describe(const Config& c) {
  static const char* levels[] = {"debug", "info", "warning", "error"};
  std::ostringstream o;
  const auto& t = c.transport;
  const MatchParams& m = c.match;
  o << "config " << c.file << "\n"
    << "  agent = " << t.agent << "\n  map = " << c.map << "\n  grid = " << m.grid << "\n  domain = " << t.domain
    << "\n  address = " << t.address << "\n  discovery_port = " << t.discovery_port << "\n  data_port = " << t.data_port
    << "\n  bandwidth_kbps = " << t.bandwidth_kbps << "\n  output_dir = " << c.output_dir
    << "\n  log_level = " << levels[static_cast<int>(c.log_level)] << "\n  claim_timeout_s = " << c.claim_timeout_s
    << "\n  request_interval_s = " << c.request_interval_s << "\n  peer_memory_mb = " << c.peer_memory_mb
    << (c.faults.any() ? "\n  test faults (" + std::string(kTestFaultsVariable) + ") = " + c.faults.text() : "")
    << "\n  reference = " << c.frameReference() << "\n  match.max_features = " << m.features.max_features
    << "\n  match.fast_threshold = " << m.features.fast_threshold
    << "\n  match.ransac_threshold_cells = " << m.ransac_threshold_cells
    << "\n  match.ransac_iterations = " << m.ransac_iterations
    << "\n  match.ransac_confidence = " << m.ransac_confidence << "\n  match.min_matches = " << m.min_matches
    << "\n  match.consensus_translation_cells = " << m.consensus_translation_cells
    << "\n  match.consensus_yaw_deg = " << degrees(m.consensus_yaw) << "\n  match.min_support = " << m.min_support
    << "\n  match.min_inliers = " << m.min_inliers << "\n  match.threads = " << m.threads
    << "\n  match.max_tilt_deg = " << degrees(m.max_tilt);
  const auto& f = t.security;
  if (f.enabled())
    o << "\n  security.ca = " << f.ca << "\n  security.certificate = " << f.certificate
      << "\n  security.private_key = " << f.private_key << "\n  security.governance = " << f.governance
      << "\n  security.permissions = " << f.permissions << "\n  security.crl = " << f.crl;
  else
    o << "\n  security: off (no [security] table)";
  if (c.ros2.enabled)
    o << "\n  ros2.domain = " << c.ros2.domain << "\n  ros2.frame = " << c.ros2.frame
      << "\n  ros2.root = " << c.treeRoot()
      << "\n  ros2.localhost_only = " << (c.ros2.localhost_only ? "true" : "false")
      << "\n  ros2.map_topic = " << (c.ros2.map_topic.empty() ? "(none: the map file)" : c.ros2.map_topic);
  else
    o << "\n  ros2: off (no [ros2] table)";
  for (const auto& p : t.peers) o << "\n  peer " << p.id << " = " << p.host << ":" << p.port;
  return o.str();
}

}  // namespace tomomap::daemon
