#include "settings.hpp"

#include <algorithm>
#include <cctype>
#include <deque>
#include <filesystem>
#include <regex>
#include <sstream>

#include "core/gravity.hpp"
#include "core/match_settings.hpp"
#include "core/text.hpp"

namespace tomomap::daemon {
namespace {

using K = SettingKind;
using V = SettingValue;
using Check = std::optional<std::string>;

const std::string& text(const V& v) { return std::get<std::string>(v); }

Check agentId(const V& v) {
  if (std::regex_match(text(v), std::regex("[A-Za-z0-9_-]{1,32}"))) return std::nullopt;
  return "must be 1 to 32 letters, digits, '-' or '_'";
}

Check ipv4(const V& v) {
  if (std::regex_match(text(v), std::regex(R"((\d{1,3})\.(\d{1,3})\.(\d{1,3})\.(\d{1,3}))"))) return std::nullopt;
  return "must be an IPv4 address such as 192.168.1.20";
}

Check existingFile(const V& v) {
  if (std::filesystem::is_regular_file(text(v))) return std::nullopt;
  return "no such file: " + text(v) + " (tomomap fleet-keys makes them)";
}

/// A ROS 2 topic name: segments of letters, digits and _, not starting with a
/// digit, separated by / (a leading / or none: relative names resolve to the root).
Check rosTopic(const V& v) {
  const std::string& name = text(v);
  const Check no = "'" + name + "' is not a ROS 2 topic name (letters, digits, _ and / only, e.g. /Laser_map)";
  if (name.empty()) return std::nullopt;  // none: the map file
  std::string rest = name.rfind('/', 0) == 0 ? name.substr(1) : name;
  if (rest.empty() || rest.back() == '/') return no;
  bool segment_start = true;
  for (char ch : rest) {
    if (ch == '/') {
      if (segment_start) return no;  // an empty segment
      segment_start = true;
      continue;
    }
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_')) return no;
    if (segment_start && std::isdigit(static_cast<unsigned char>(ch))) return no;
    segment_start = false;
  }
  return std::nullopt;
}

const char* const kLevels[] = {"debug", "info", "warning", "error"};

/// "X, Y, Z" as a direction (any length but zero); none where it is not one.
std::optional<Eigen::Vector3d> direction(const std::string& text) {
  std::istringstream in(text);
  Eigen::Vector3d v;
  char comma = 0;
  if (!(in >> v.x() >> comma) || comma != ',' || !(in >> v.y() >> comma) || comma != ',' || !(in >> v.z()))
    return std::nullopt;
  in >> std::ws;
  if (!in.eof() || !v.allFinite() || !(v.norm() > 0)) return std::nullopt;
  return v;
}

std::string directionText(const Eigen::Vector3d& v) {
  std::ostringstream o;
  o << v.x() << ", " << v.y() << ", " << v.z();
  return o.str();
}

/// Declares settings in the reference's order, one statement each.
class Declare {
 public:
  Setting& operator()(std::string key, K kind, std::string unit, Reload reload, std::string doc) {
    Setting s;
    s.key = std::move(key);
    s.kind = kind;
    s.unit = std::move(unit);
    s.reload = reload;
    s.doc = std::move(doc);
    all.push_back(std::move(s));
    return all.back();
  }
  /// A matcher setting (match_settings.hpp) at `key`, reading Config::match.
  Setting& match(const MatchSetting& m, std::string key) {
    Setting& s = (*this)(std::move(key), m.kind, m.unit, Reload::AtOnce, m.doc);
    s.lo = m.lo, s.hi = m.hi;
    s.get = [get = m.get](const Config& c) { return get(c.match); };
    s.set = [set = m.set](Config& c, const V& v) { set(c.match, v); };
    return s;
  }
  std::deque<Setting> all;  ///< a deque: each reference returned stays valid as more are declared
};

std::vector<Setting> declare() {
  Declare d;
  auto range = [](Setting& s, double lo, double hi) -> Setting& {
    s.lo = lo, s.hi = hi;
    return s;
  };
  {
    Setting& s =
        d("agent", K::Text, "", Reload::Restart, "this agent's id: 1-32 of `A-Z a-z 0-9 - _`; unique in the fleet");
    s.required = true;
    s.check = agentId;
    bindField(s, [](Config& c) { return &c.transport.agent; });
  }
  {
    Setting& s = d("map", K::Text, "path", Reload::AtOnce,
                   "the robot's map, gravity-aligned or leaning as its SLAM saved it (levelled: `map_up`) (PCD, PLY, "
                   "XYZ/CSV text, OctoMap .bt/.ot; docs/cli.md \"Map "
                   "files\"); followed: a rewrite (in place or by rename) is read 1 s after the last write; a file "
                   "that does not exist yet is waited for (`--check` warns), one that exists but cannot be read is "
                   "an error (exit 2)");
    s.path = true;
    s.default_text = "required (unless `[ros2]` `map_topic`)";
    bindField(s, [](Config& c) { return &c.map; });
  }
  {
    Setting& s = d("map_up", K::Text, "X, Y, Z", Reload::AtOnce,
                   "the map's up direction in its own frame where it is known (its SLAM's gravity estimate, an "
                   "IMU's), e.g. \"0.05, -0.02, 1\", within " +
                       fixed(degrees(kMaxLevelable), 0) +
                       " deg of z: the map is levelled by it instead of by the estimate read off its floors "
                       "(docs/operations.md, \"Maps that lean\")");
    s.default_text = "none: estimated";
    s.shown = [](const Config& c) { return c.map_up ? directionText(*c.map_up) : "(none: estimated)"; };
    s.check = [](const V& v) -> Check {
      const auto up = direction(text(v));
      if (!up) return "must be a non-zero direction \"X, Y, Z\" (three numbers separated by commas)";
      // What peers accept (levelableUp): a map levelled further is refused by every one of them.
      if (!levelableUp(up->normalized()))
        return "leans " + fixed(degrees(std::acos(std::clamp(up->normalized().z(), -1.0, 1.0))), 1) +
               " deg from z: a map is levelled by at most " + fixed(degrees(kMaxLevelable), 0) +
               " deg (its axes may be swapped: give its frame's up, z of the map's frame turned)";
      return std::nullopt;
    };
    s.get = [](const Config& c) -> V { return c.map_up ? directionText(*c.map_up) : std::string(); };
    s.set = [](Config& c, const V& v) { c.map_up = direction(text(v)); };
  }
  d.match(matchSetting("grid"), "grid");
  bindField(range(d("domain", K::Integer, "", Reload::Rejoin, "DDS domain id, the same on every agent"), 0, 232),
            [](Config& c) { return &c.transport.domain; });
  {
    Setting& s = d("address", K::Text, "IPv4", Reload::Rejoin, "this agent's address, where peers reach it");
    s.check = ipv4;
    bindField(s, [](Config& c) { return &c.transport.address; });
  }
  {
    Setting& s =
        range(d("discovery_port", K::Integer, "UDP port", Reload::Rejoin, "discovery traffic (peers list this port)"),
              1024, 65534);
    s.required = true;
    bindField(s, [](Config& c) { return &c.transport.discovery_port; });
  }
  {
    Setting& s =
        range(d("data_port", K::Integer, "UDP port", Reload::Rejoin, "user data; not discovery_port"), 1024, 65535);
    s.default_text = "discovery_port + 1";
    bindField(s, [](Config& c) { return &c.transport.data_port; });
  }
  bindField(range(d("bandwidth_kbps", K::Number, "kbit/s", Reload::Rejoin,
                    "budget for everything the daemon sends (slices, discovery, acknowledgements, requests, "
                    "estimates), counted with IP, UDP and Ethernet headers and held over any 5 s window "
                    "(docs/protocol.md)"),
                  64, 10'000'000),
            [](Config& c) { return &c.transport.bandwidth_kbps; });
  {
    Setting& s = d("output_dir", K::Text, "path", Reload::AtOnce,
                   "`transforms.json`, `frame.json`, `status.json` (read by `tomomap status`); under the systemd "
                   "unit the default is its `StateDirectory`");
    s.path = true;
    s.default_text = "`$STATE_DIRECTORY`, else \"/var/lib/tomomap\"";
    bindField(s, [](Config& c) { return &c.output_dir; });
  }
  {
    Setting& s = d("log_level", K::Text, "", Reload::AtOnce, "`debug`, `info`, `warning` or `error`");
    s.check = [](const V& v) -> Check {
      for (const char* level : kLevels)
        if (text(v) == level) return std::nullopt;
      return "must be debug, info, warning or error";
    };
    s.get = [](const Config& c) -> V { return std::string(kLevels[static_cast<int>(c.log_level)]); };
    s.set = [](Config& c, const V& v) {
      for (int i = 0; i < 4; ++i)
        if (text(v) == kLevels[i]) c.log_level = static_cast<LogLevel>(i);
    };
  }
  bindField(range(d("claim_timeout_s", K::Number, "s", Reload::AtOnce,
                    "a claim without a result after this long is void and the next agent in the pair's order "
                    "computes it; also how long each agent waits before taking a pair from the one ahead of it "
                    "in that order (docs/protocol.md, \"Claim, compute, broadcast\")"),
                  1, 3600),
            [](Config& c) { return &c.claim_timeout_s; });
  bindField(range(d("request_interval_s", K::Number, "s", Reload::AtOnce,
                    "ask a peer again for missing slices after this long without progress"),
                  0.1, 600),
            [](Config& c) { return &c.request_interval_s; });
  bindField(range(d("peer_memory_mb", K::Number, "MB", Reload::AtOnce,
                    "memory one peer's map may take on this agent: an announcement whose payload plus one raster "
                    "image exceeds it is refused before anything is allocated, and a map whose inflated "
                    "occupancy would exceed it is refused as it arrives (one log line, counted as "
                    "`rejected_samples`)"),
                  1, 65536),
            [](Config& c) { return &c.peer_memory_mb; });
  {
    Setting& s = d("reference", K::Text, "agent id", Reload::AtOnce,
                   "whose map is the fleet's frame: `frame.json` gives every agent's pose in it (this agent or a "
                   "peer; every agent of a fleet should name the same one)");
    s.default_text = "the lowest agent id of the fleet";
    s.shown = [](const Config& c) { return c.frameReference(); };
    bindField(s, [](Config& c) { return &c.reference; });
  }
  for (const MatchSetting& m : matchSettings())
    if (m.key != "grid") d.match(m, "match." + m.key);
  {
    Setting& s = d("peer.id", K::Text, "", Reload::Rejoin,
                   "a peer's agent id; samples from ids not listed are dropped and counted");
    s.required = true;
    s.check = agentId;
    Setting& h = d("peer.host", K::Text, "IPv4", Reload::Rejoin, "the peer's address");
    h.required = true;
    h.check = ipv4;
    Setting& p =
        range(d("peer.port", K::Integer, "UDP port", Reload::Rejoin, "the peer's `discovery_port`"), 1024, 65534);
    p.required = true;
  }
  const auto security = [&](const char* key, const char* doc) -> Setting& {
    Setting& s = d(std::string("security.") + key, K::Text, "path", Reload::Rejoin, doc);
    s.path = true;
    s.check = existingFile;
    s.default_text = "required with `[security]`";
    return s;
  };
  bindField(security("ca",
                     "the fleet CA's certificate (PEM): it must have issued every peer's certificate and signed "
                     "the governance and permissions documents. With the `[security]` table every agent of the "
                     "fleet needs one"),
            [](Config& c) { return &c.transport.security.ca; })
      .default_text = "none: security off";
  bindField(security("certificate", "this agent's certificate (PEM); its common name must be `agent` (peers check it)"),
            [](Config& c) { return &c.transport.security.certificate; });
  bindField(security("private_key", "its private key (PEM, readable by the service only)"),
            [](Config& c) { return &c.transport.security.private_key; });
  bindField(security("governance", "the signed domain rules (S/MIME), the same on every agent"),
            [](Config& c) { return &c.transport.security.governance; });
  bindField(security("permissions", "this agent's signed grant (S/MIME)"),
            [](Config& c) { return &c.transport.security.permissions; });
  bindField(security("crl", "optional: the fleet's revocation list (PEM); certificates on it cannot join"),
            [](Config& c) { return &c.transport.security.crl; })
      .default_text = "none";
  {
    Setting& s = d("ros2.enabled", K::Flag, "", Reload::RestartsRos2,
                   "publish the fleet's frames on ROS 2's `/tf_static` and this daemon's health on `/diagnostics` "
                   "(docs/operations.md, \"ROS 2\"); without the table, off");
    s.default_text = "true with `[ros2]`";
    bindField(s, [](Config& c) { return &c.ros2.enabled; });
  }
  bindField(range(d("ros2.domain", K::Integer, "", Reload::RestartsRos2,
                    "the ROS 2 nodes' `ROS_DOMAIN_ID` (independent of `domain` above)"),
                  0, 232),
            [](Config& c) { return &c.ros2.domain; });
  {
    Setting& s =
        d("ros2.frame", K::Text, "", Reload::RestartsRos2, "frame id of each robot's map; `{agent}` becomes its id");
    s.check = [](const V& v) -> Check {
      if (text(v).find("{agent}") != std::string::npos) return std::nullopt;
      return "must contain {agent} (each map needs its own frame)";
    };
    bindField(s, [](Config& c) { return &c.ros2.frame; });
  }
  {
    Setting& s = d("ros2.root", K::Text, "agent id", Reload::RestartsRos2,
                   "the tree's root frame: every other map hangs from it, with its pose in the fleet's frame (this "
                   "agent or a peer)");
    s.default_text = "`reference`";
    s.shown = [](const Config& c) { return c.treeRoot(); };
    bindField(s, [](Config& c) { return &c.ros2.root; });
  }
  {
    Setting& s = d("ros2.world", K::Text, "", Reload::RestartsRos2,
                   "a frame above every map, as multi-robot map mergers name it (e.g. `world`): every placed map "
                   "hangs from it with its pose in the root's map (the root's the identity), so the root's map is "
                   "one child among others");
    s.default_text = "none: the root's map is the tree's root";
    s.check = [](const V& v) -> Check {
      if (text(v).find("{agent}") == std::string::npos && text(v).find(' ') == std::string::npos) return std::nullopt;
      return "must be one frame id, without {agent} or spaces";
    };
    bindField(s, [](Config& c) { return &c.ros2.world; });
  }
  bindField(d("ros2.localhost_only", K::Flag, "", Reload::RestartsRos2,
              "reach ROS 2 nodes on this robot only, under any ROS 2 discovery setting that keeps them on it "
              "(`ROS_LOCALHOST_ONLY=1`, Jazzy's `LOCALHOST`, static peers on this host), and send nothing to "
              "the network; false: multicast discovery on every interface too, for ROS 2's defaults, whose "
              "traffic also crosses the robots' link (docs/operations.md, \"ROS 2\")"),
            [](Config& c) { return &c.ros2.localhost_only; });
  {
    Setting& s = d("ros2.map_topic", K::Text, "ROS 2 topic name", Reload::RestartsRos2,
                   "read the robot's map from this topic (of `map_type`; its SLAM's map cloud, e.g. `/Laser_map`, or "
                   "octomap_server's `/octomap_binary`) instead of the `map` file, which must then be absent; a "
                   "`sensor_msgs/PointCloud2`'s x, y, z as float32 or "
                   "float64 in any field layout, organised or not (holes dropped and counted); big-endian clouds "
                   "are refused with a log line; reliable, volatile or transient local; each new message is a map "
                   "update, described once the previous one is done and the first waiting message is 1 s old (the "
                   "newest wins); its frame id is logged and in `status.json` (docs/operations.md, \"ROS 2\")");
    s.check = rosTopic;
    s.default_text = "none";
    s.shown = [](const Config& c) { return c.ros2.map_topic.empty() ? "(none: the map file)" : c.ros2.map_topic; };
    bindField(s, [](Config& c) { return &c.ros2.map_topic; });
  }
  {
    Setting& s = d("ros2.map_type", K::Text, "", Reload::RestartsRos2,
                   "what `map_topic` carries: `sensor_msgs/PointCloud2`, or `octomap_msgs/Octomap` (octomap_server's "
                   "`/octomap_binary` or `/octomap_full`: binary or full trees of type `OcTree`, read by octomap's "
                   "own deserialiser; the map is the centres of the occupied voxels at the tree's resolution)");
    s.check = [](const V& v) -> Check {
      for (const auto type : {transport::MapMessageType::PointCloud2, transport::MapMessageType::Octomap})
        if (text(v) == mapTypeName(type)) return std::nullopt;
      return "must be sensor_msgs/PointCloud2 or octomap_msgs/Octomap";
    };
    s.get = [](const Config& c) -> V { return std::string(mapTypeName(c.ros2.map_type)); };
    s.set = [](Config& c, const V& v) {
      c.ros2.map_type = text(v) == mapTypeName(transport::MapMessageType::Octomap)
                            ? transport::MapMessageType::Octomap
                            : transport::MapMessageType::PointCloud2;
    };
  }
  bindField(d("fleet_map.enabled", K::Flag, "", Reload::AtOnce,
              "build the fleet's map here from the slices every agent shares (no byte more on the link): "
              "`fleet_map.pcd`, `.pgm` + `.yaml` and `.png` beside `transforms.json`, and with `[ros2]` "
              "`/fleet_map` and `/fleet_map_grid` (docs/operations.md, \"The fleet's map\")"),
            [](Config& c) { return &c.fleet_map.enabled; });
  bindField(range(d("fleet_map.band_low", K::Number, "m", Reload::AtOnce,
                    "the 2D grid's obstacles start this high above the floor (the floor's own cells stay out)"),
                  -10, 100),
            [](Config& c) { return &c.fleet_map.band.low; });
  bindField(range(d("fleet_map.band_high", K::Number, "m", Reload::AtOnce,
                    "and end this high: the robot's body height; above `band_low`"),
                  -10, 100),
            [](Config& c) { return &c.fleet_map.band.high; });
  bindField(range(d("fleet_map.interval_s", K::Number, "s", Reload::AtOnce,
                    "build the fleet's map again when a map or the fleet's frame changed and then stayed so "
                    "this long (while they keep changing, every 6 times this), at most this often; in the "
                    "background (matching and sending never wait on it)"),
                  1, 3600),
            [](Config& c) { return &c.fleet_map.interval_s; });
  return {d.all.begin(), d.all.end()};
}

}  // namespace

std::string Setting::table() const {
  const size_t dot = key.find('.');
  return dot == std::string::npos ? "" : key.substr(0, dot);
}

std::string Setting::name() const {
  const size_t dot = key.find('.');
  return dot == std::string::npos ? key : key.substr(dot + 1);
}

const std::vector<Setting>& settings() {
  static const std::vector<Setting> all = declare();
  return all;
}

const Setting& setting(const std::string& key) { return findSetting(settings(), key); }

bool isSetting(const std::string& key) {
  const auto& all = settings();
  return std::any_of(all.begin(), all.end(), [&](const Setting& s) { return s.key == key; });
}

std::vector<std::string> changed(const Config& a, const Config& b, Reload reload) {
  std::vector<std::string> keys;
  for (const auto& s : settings())
    if (s.reload == reload && !s.perElement() && s.get(a) != s.get(b)) keys.push_back(s.key);
  return keys;
}

std::string referenceTable() {
  static const char* kinds[] = {"boolean", "integer", "number", "string"};
  static const char* reloads[] = {"at once", "rejoins the network", "restarts the ROS 2 node", "needs a restart"};
  const Config defaults;
  std::ostringstream o;
  o << "| key | type | default | unit | range | on reload | meaning |\n|---|---|---|---|---|---|---|\n";
  for (const auto& s : settings()) {
    const std::string t = s.table();
    const std::string heading = t.empty() ? "" : t == "peer" ? "`[[peer]]` " : "`[" + t + "]` ";
    std::string value = s.default_text;
    if (value.empty() && s.required) value = "required";
    if (value.empty() && s.get) {
      value = settingText(s.get(defaults));
      if (s.kind == SettingKind::Text) value = "\"" + value + "\"";
    }
    std::string range;
    if (s.hasRange()) range = settingText(s.lo) + " to " + settingText(s.hi);
    o << "| " << heading << "`" << s.name() << "` | " << kinds[static_cast<int>(s.kind)] << " | " << value << " | "
      << s.unit << " | " << range << " | " << reloads[static_cast<int>(s.reload)] << " | " << s.doc << " |\n";
  }
  return o.str();
}

}  // namespace tomomap::daemon
