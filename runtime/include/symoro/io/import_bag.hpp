// ROS 2 bags into the project's log (docs/dataset.md, "ROS 2 bags"): an MCAP file, or a bag
// folder (metadata.yaml naming its MCAP files, in order), read by the project's own MCAP reader
// (io/mcap.hpp); the sensor_msgs/msg/JointState messages on one topic decoded (io/
// ros2_joint_state.hpp) and matched to the robot's joints by name.
//
// Rows: the messages that carry the same stamp (header.stamp, or the receive time with
// StampSource::receive) make one row, so a driver that publishes the arm and the hand apart, or
// several publishers on one topic, give whole rows. A stamp whose messages lack one of the
// robot's joints (a partial row) is left out and counted; two messages of one stamp that give a
// joint different values are an error. Names the robot does not have (a gripper's, another
// arm's) are ignored and listed. Time starts at 0 at the first row (the absolute start is in the
// remarks). Velocity is measured when every row has it, else differentiated from q (said).
// Effort is torque as published, or current times the joints' torque constants. A file cut short
// (no footer) gives the messages before the cut, said in the remarks.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "symoro/io/import.hpp"

namespace symoro::io {

// Whether `input` is a ROS 2 bag: a folder, or a file whose name ends in .mcap.
bool is_bag(const std::filesystem::path& input);

// The MCAP files of a bag, in order: the file itself, or a folder's metadata.yaml's
// relative_file_paths. DataError naming metadata.yaml and its line for another storage
// (sqlite3: convert it with `ros2 bag convert`), a missing file, a folder without metadata.yaml.
std::vector<std::filesystem::path> bag_files(const std::filesystem::path& input);

// robot.yaml's torque constants (N m/A), `torque_constant` of each entry of `joints`, in order;
// empty when no joint has one. DataError(robot.yaml, line) when some joints have one and others
// not, or one is not a positive number.
std::vector<double> robot_torque_constants(const std::filesystem::path& robot_yaml);

// The settings by name (dynid import's options, symoro.import_logs' keywords): stamp "header" |
// "receive", effort "torque" | "current"; torque constants one for all `joints` or one each, else,
// for effort "current", robot.yaml's (robot_yaml, when it is a file). std::invalid_argument naming what is
// wrong (an unknown word, constants with effort "torque", the wrong number of constants).
BagSettings bag_settings(const std::string& topic, const std::string& stamp, const std::string& effort,
                         const std::vector<double>& torque_constants, std::size_t joints,
                         const std::filesystem::path& robot_yaml = {});

// One bag, converted as described above. DataError naming the bag (and the MCAP file and byte,
// or the message's index and receive time) for: no message on the topic (the topics there are
// listed), a topic of another type, a message that does not decode, a robot joint no message
// names (the names seen are listed), header stamps all zero (use StampSource::receive), two
// values of one joint at one stamp, fewer than 4 whole rows, no effort.
ImportedLog import_bag(const std::filesystem::path& input, const BagSettings& settings, const ImportTarget& target);

}  // namespace symoro::io
