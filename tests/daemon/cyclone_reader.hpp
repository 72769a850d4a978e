#pragma once
// A ROS 2 node of the other DDS vendor: Eclipse Cyclone DDS, as rmw_cyclonedds
// configures it for each ROS 2 discovery setting, reading tomomapd's topics
// with ROS 2's own message types (tests/ros2/cyclone_ros2_reader.c).
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "support.hpp"

namespace tomomap::test {

/// A ROS 2 discovery setting as rmw_cyclonedds_cpp configures Cyclone DDS for it.
struct Ros2Setting {
  std::string name;
  std::string cyclonedds_uri;  ///< what rmw_cyclonedds builds (empty: Cyclone's defaults)
};

inline std::string cyclone(const std::string& inside) { return "<CycloneDDS><Domain>" + inside + "</Domain></CycloneDDS>"; }

/// Humble's ROS_LOCALHOST_ONLY=1: the loopback interface alone.
inline const Ros2Setting kHumbleLocalhostOnly{
    "ROS_LOCALHOST_ONLY=1 (Humble)",
    cyclone("<General><NetworkInterfaceAddress>127.0.0.1</NetworkInterfaceAddress></General>")};
/// Jazzy's LOCALHOST range: no multicast, localhost as a static peer.
inline const Ros2Setting kJazzyLocalhost{"ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST (Jazzy)",
                                  cyclone("<General><AllowMulticast>false</AllowMulticast></General><Discovery>"
                                          "<ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>32</"
                                          "MaxAutoParticipantIndex><Peers><Peer address=\"localhost\"/></Peers></"
                                          "Discovery>")};
/// Jazzy's SUBNET range with ROS_STATIC_PEERS=127.0.0.1: multicast, and the peer.
inline const Ros2Setting kJazzySubnetStaticPeer{
    "ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET, ROS_STATIC_PEERS=127.0.0.1 (Jazzy)",
    cyclone("<Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>32</"
            "MaxAutoParticipantIndex><Peers><Peer address=\"127.0.0.1\"/></Peers></Discovery>")};
/// ROS 2's defaults (Humble's, and Jazzy's SUBNET range): multicast on the network.
inline const Ros2Setting kDefaults{"the defaults (Humble; Jazzy's SUBNET)", ""};
/// Jazzy's OFF range: no multicast, no peers, a domain tag of the process's own.
inline const Ros2Setting kJazzyOff{"ROS_AUTOMATIC_DISCOVERY_RANGE=OFF (Jazzy)",
                            cyclone("<General><AllowMulticast>false</AllowMulticast></General><Discovery>"
                                    "<ParticipantIndex>none</ParticipantIndex><Tag>ros_discovery_off_1</Tag></"
                                    "Discovery>")};

/// The last sample a Cyclone DDS reader under `setting` took from rt/`topic`
/// on `domain` once it was done (`until`: cyclone_ros2_reader's third
/// argument); null if it never was.
inline nlohmann::json readWithCyclone(const Ros2Setting& setting, const std::string& topic, int domain,
                               const std::string& until, std::string& output, int seconds = 120) {
  const auto r =
      runBinary("env", "CYCLONEDDS_URI='" + setting.cyclonedds_uri + "' " CYCLONE_ROS2_READER_BIN " " + topic + " " +
                           std::to_string(domain) + " '" + until + "' " + std::to_string(seconds));
  output = r.output;
  nlohmann::json last;
  std::istringstream lines(r.output);
  for (std::string line; std::getline(lines, line);)
    if (!line.empty() && line[0] == '{') last = nlohmann::json::parse(line);
  return r.exit_code == 0 ? last : nlohmann::json();
}


}  // namespace tomomap::test
