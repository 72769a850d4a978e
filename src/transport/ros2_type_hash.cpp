#include "ros2_type_hash.hpp"

#include <openssl/evp.h>

#include <map>
#include <set>
#include <stdexcept>
#include <utility>

namespace tomomap::transport {
namespace {

/// A message's fields as its .msg file lists them: name, type ("float64",
/// "pkg/msg/Type", a trailing "[]" for an unbounded sequence).
using Fields = std::vector<std::pair<std::string, std::string>>;

/// The messages tomomapd publishes and reads, and every message they refer to
/// (ROS 2 Jazzy's common_interfaces, rcl_interfaces, geometry2, octomap_msgs).
const std::map<std::string, Fields>& definitions() {
  static const std::map<std::string, Fields> all{
      {"builtin_interfaces/msg/Time", {{"sec", "int32"}, {"nanosec", "uint32"}}},
      {"std_msgs/msg/Header", {{"stamp", "builtin_interfaces/msg/Time"}, {"frame_id", "string"}}},
      {"geometry_msgs/msg/Vector3", {{"x", "float64"}, {"y", "float64"}, {"z", "float64"}}},
      {"geometry_msgs/msg/Point", {{"x", "float64"}, {"y", "float64"}, {"z", "float64"}}},
      {"geometry_msgs/msg/Quaternion", {{"x", "float64"}, {"y", "float64"}, {"z", "float64"}, {"w", "float64"}}},
      {"geometry_msgs/msg/Pose", {{"position", "geometry_msgs/msg/Point"}, {"orientation", "geometry_msgs/msg/Quaternion"}}},
      {"geometry_msgs/msg/Transform",
       {{"translation", "geometry_msgs/msg/Vector3"}, {"rotation", "geometry_msgs/msg/Quaternion"}}},
      {"geometry_msgs/msg/TransformStamped",
       {{"header", "std_msgs/msg/Header"}, {"child_frame_id", "string"}, {"transform", "geometry_msgs/msg/Transform"}}},
      {"tf2_msgs/msg/TFMessage", {{"transforms", "geometry_msgs/msg/TransformStamped[]"}}},
      {"diagnostic_msgs/msg/KeyValue", {{"key", "string"}, {"value", "string"}}},
      {"diagnostic_msgs/msg/DiagnosticStatus",
       {{"level", "byte"},
        {"name", "string"},
        {"message", "string"},
        {"hardware_id", "string"},
        {"values", "diagnostic_msgs/msg/KeyValue[]"}}},
      {"diagnostic_msgs/msg/DiagnosticArray",
       {{"header", "std_msgs/msg/Header"}, {"status", "diagnostic_msgs/msg/DiagnosticStatus[]"}}},
      {"sensor_msgs/msg/PointField", {{"name", "string"}, {"offset", "uint32"}, {"datatype", "uint8"}, {"count", "uint32"}}},
      {"sensor_msgs/msg/PointCloud2",
       {{"header", "std_msgs/msg/Header"},
        {"height", "uint32"},
        {"width", "uint32"},
        {"fields", "sensor_msgs/msg/PointField[]"},
        {"is_bigendian", "bool"},
        {"point_step", "uint32"},
        {"row_step", "uint32"},
        {"data", "uint8[]"},
        {"is_dense", "bool"}}},
      {"nav_msgs/msg/MapMetaData",
       {{"map_load_time", "builtin_interfaces/msg/Time"},
        {"resolution", "float32"},
        {"width", "uint32"},
        {"height", "uint32"},
        {"origin", "geometry_msgs/msg/Pose"}}},
      {"nav_msgs/msg/OccupancyGrid",
       {{"header", "std_msgs/msg/Header"}, {"info", "nav_msgs/msg/MapMetaData"}, {"data", "int8[]"}}},
      {"octomap_msgs/msg/Octomap",
       {{"header", "std_msgs/msg/Header"},
        {"binary", "bool"},
        {"id", "string"},
        {"resolution", "float64"},
        {"data", "int8[]"}}},
  };
  return all;
}

/// rosidl's field type ids (type_description_interfaces/msg/FieldType.msg);
/// a nested message is 1; an unbounded sequence adds 144.
const std::map<std::string, int>& primitiveIds() {
  static const std::map<std::string, int> ids{{"int8", 2},    {"uint8", 3},    {"int32", 6}, {"uint32", 7},
                                              {"float32", 10}, {"float64", 11}, {"bool", 15}, {"byte", 16},
                                              {"string", 17}};
  return ids;
}
constexpr int kNestedType = 1, kUnboundedSequence = 144;

const Fields& fieldsOf(const std::string& type) {
  const auto it = definitions().find(type);
  if (it == definitions().end()) throw std::logic_error("no ROS 2 definition of " + type + " here");
  return it->second;
}

/// "pkg/msg/Type" of "pkg/msg/Type[]"; a primitive stays itself.
std::string baseOf(const std::string& type) {
  return type.size() > 2 && type.compare(type.size() - 2, 2, "[]") == 0 ? type.substr(0, type.size() - 2) : type;
}

void referencesOf(const std::string& type, std::set<std::string>& found) {
  for (const auto& [name, field_type] : fieldsOf(type)) {
    const std::string base = baseOf(field_type);
    if (!primitiveIds().count(base) && found.insert(base).second) referencesOf(base, found);
  }
}

/// One IndividualTypeDescription as Python's json.dumps writes it with
/// separators (', ', ': '), the form the hash is taken over.
std::string individualDescription(const std::string& type) {
  std::string out = "{\"type_name\": \"" + type + "\", \"fields\": [";
  bool first = true;
  for (const auto& [name, field_type] : fieldsOf(type)) {
    const std::string base = baseOf(field_type);
    const auto primitive = primitiveIds().find(base);
    const bool nested = primitive == primitiveIds().end();
    const int id = (nested ? kNestedType : primitive->second) + (base != field_type ? kUnboundedSequence : 0);
    out += std::string(first ? "" : ", ") + "{\"name\": \"" + name + "\", \"type\": {\"type_id\": " +
           std::to_string(id) + ", \"capacity\": 0, \"string_capacity\": 0, \"nested_type_name\": \"" +
           (nested ? base : "") + "\"}}";
    first = false;
  }
  return out + "]}";
}

}  // namespace

std::string typeHash(const std::string& type) {
  std::set<std::string> references;  // sorted by name, as rosidl sorts them
  referencesOf(type, references);
  std::string text = "{\"type_description\": " + individualDescription(type) + ", \"referenced_type_descriptions\": [";
  bool first = true;
  for (const auto& r : references) {
    text += (first ? "" : ", ") + individualDescription(r);
    first = false;
  }
  text += "]}";
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (EVP_Digest(text.data(), text.size(), digest, &length, EVP_sha256(), nullptr) != 1)
    throw std::runtime_error("SHA-256 failed");
  static const char* hex = "0123456789abcdef";
  std::string out = "RIHS01_";
  for (unsigned int i = 0; i < length; ++i) {
    out += hex[digest[i] >> 4];
    out += hex[digest[i] & 15];
  }
  return out;
}

std::vector<uint8_t> typeHashUserData(const std::string& type) {
  const std::string text = "typehash=" + typeHash(type) + ";";
  return {text.begin(), text.end()};
}

}  // namespace tomomap::transport
