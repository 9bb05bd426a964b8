// sensor_msgs/msg/JointState as ROS 2 stores it in a bag: its definition checked against the
// schema the bag carries (ros2msg text), and its bytes decoded from CDR (OMG XCDR1, the ROS 2
// default: a 4-byte encapsulation header naming the byte order, then each field aligned to its
// own size, from the end of that header).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace symoro::io::ros2 {

inline constexpr const char* kJointStateType = "sensor_msgs/msg/JointState";

struct JointState {
  std::int32_t sec = 0;  // header.stamp
  std::uint32_t nanosec = 0;
  std::string frame_id;
  std::vector<std::string> name;
  std::vector<double> position, velocity, effort;  // each empty or as long as name
};

// Throws std::invalid_argument naming what differs when a ros2msg definition's own fields are
// not JointState's (std_msgs/Header header, string[] name, float64[] position, velocity, effort).
void check_joint_state_definition(const std::string& ros2msg_text);

// Decodes one message. Throws std::invalid_argument naming the field and the byte at which the
// bytes stop making sense (cut short, a length past the end, an unknown encapsulation, an
// array whose length is neither 0 nor the names').
JointState decode_joint_state(const std::uint8_t* data, std::size_t size);

}  // namespace symoro::io::ros2
