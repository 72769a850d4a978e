#pragma once
// ROS 2's type hashes (REP-2016, "RIHS01"): since Iron every ROS 2 endpoint
// carries its message type's hash in its USER_DATA ("typehash=RIHS01_<hex>;"),
// and rmw implementations and DDS bridges warn about endpoints without it.
// The hash is computed here as rosidl_generator_type_description does it,
// from the messages' .msg definitions (ros2_type_hash.cpp), so a type's hash
// follows from its fields, not from a copied constant.
#include <cstdint>
#include <string>
#include <vector>

namespace tomomap::transport {

/// The RIHS01 hash of the ROS 2 message `type` ("tf2_msgs/msg/TFMessage"),
/// as "RIHS01_" and 64 lowercase hex digits. Throws std::logic_error for a
/// type whose definition is not among the ones tomomapd uses.
std::string typeHash(const std::string& type);

/// The USER_DATA of an endpoint of `type` as rmw_fastrtps and rmw_cyclonedds
/// write it: "typehash=RIHS01_...;" (ASCII, no terminator).
std::vector<uint8_t> typeHashUserData(const std::string& type);

}  // namespace tomomap::transport
