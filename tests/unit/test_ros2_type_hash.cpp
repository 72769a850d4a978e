// ROS 2's type hashes (transport/ros2_type_hash.hpp) against the values ROS 2
// itself publishes for these types.
#include <gtest/gtest.h>

#include <stdexcept>

#include "transport/ros2_type_hash.hpp"

using namespace tomomap::transport;

TEST(Ros2TypeHash, EachMessagesHashIsTheOneRos2Publishes) {
  // std_msgs/Header and builtin_interfaces/Time: as every Iron and Jazzy type support carries them.
  EXPECT_EQ(typeHash("std_msgs/msg/Header"), "RIHS01_f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01");
  EXPECT_EQ(typeHash("builtin_interfaces/msg/Time"),
            "RIHS01_b106235e25a4c5ed35098aa0a61a3ee9c9b18d197f398b0e4206cea9acf9c197");
  // PointCloud2: the value rcl's own test (rcl/test/rcl/test_type_hash.cpp) copies from generated code.
  EXPECT_EQ(typeHash("sensor_msgs/msg/PointCloud2"),
            "RIHS01_9198cabf7da3796ae6fe19c4cb3bdd3525492988c70522628af5daa124bae2b5");
  // TFMessage and OccupancyGrid: what `ros2 topic info -v` prints for /tf_static and a costmap on Jazzy.
  EXPECT_EQ(typeHash("tf2_msgs/msg/TFMessage"),
            "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087");
  EXPECT_EQ(typeHash("nav_msgs/msg/OccupancyGrid"),
            "RIHS01_8d348150c12913a31ee0ec170fbf25089e4745d17035792a1ba94d6f0bc0cfc7");
  // A .msg `byte` (DiagnosticStatus.level) is an octet, not a uint8: its own id.
  EXPECT_EQ(typeHash("diagnostic_msgs/msg/DiagnosticArray"),
            "RIHS01_5a8a36efb05fb25070fa0fb3810290c0e6cd4862b54a8fb975a1ee8dc55a333e");
  EXPECT_EQ(typeHash("geometry_msgs/msg/TransformStamped"),
            "RIHS01_0a241f87d04668d94099cbb5ba11691d5ad32c2f29682e4eb5653424bd275206");

  const std::vector<uint8_t> user_data = typeHashUserData("std_msgs/msg/Header");
  EXPECT_EQ(std::string(user_data.begin(), user_data.end()),
            "typehash=RIHS01_f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01;");
  EXPECT_THROW(typeHash("std_msgs/msg/NoSuchType"), std::logic_error);
}
