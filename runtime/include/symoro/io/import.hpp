// Importing logs exported by a robot's own controller (docs/dataset.md): CSV, ';'- or
// whitespace-separated text, with or without a header row, '#' comment lines, any sample
// rate, irregular stamps. A mapping says which columns hold time, q, qd (optional), tau and
// the optional references, and in which units; the importer converts to the project's log
// (log.hpp, SI units) and writes a dataset folder (dataset.hpp) of one log per input.
//
// Column selectors (the mapping's values):
//   by header name:  "t" (one column), "pos_*" ('*' = joint number 1..n), "pos_%" ('%' = 0..n-1),
//                    "{name}_pos" (the robot's joint names), or a list "a,b,c" of n names
//   by position:     "1" (one column), "2-8" (columns 2 to 8, 1-based), "2,4,6,8-10"
// Units: time s|ms|us|ns; angle rad|deg, which also sets velocity (angle/s), acceleration
// (angle/s^2) and the references; prismatic joints are never scaled (m, m/s). tau is multiplied
// by torque_scale.
//
// Repeated samples, judged on the measured columns (q, qd when mapped, tau; the references are
// the controller's own and advance even when a read is stale):
//   stale row:  same values as the previous row, later stamp (the logger read the same state
//               twice): kept in the log, counted and listed (preprocessing leaves it out).
//   duplicate:  same stamp and same values as the previous row: counted, listed, not written.
// Errors (DataError naming the input file and its 1-based line, the column where one is at
// fault): a stamp equal to the previous one with other values, time going backwards, a field
// that is not a finite number, a row with another field count than the header (or the first
// row), a pattern matching another number of columns than the robot has joints, a last line
// without its newline (the file was cut while it was written).
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "symoro/io/log.hpp"
#include "symoro/model_info.hpp"

namespace symoro::io {

enum class TimeUnit { s, ms, us, ns };
enum class AngleUnit { rad, deg };
enum class HeaderRow { automatic, present, absent };               // automatic: a first row with a non-number
enum class Delimiter { automatic, comma, semicolon, whitespace };  // automatic: ',' then ';' then blanks

struct ImportMapping {
  // Column selectors; "" when absent. time, q and tau are required; q_ref, qd_ref and qdd_ref
  // come together or not at all.
  std::string time, q, qd, tau, q_ref, qd_ref, qdd_ref;
  TimeUnit time_unit = TimeUnit::s;
  AngleUnit angle_unit = AngleUnit::rad;
  double torque_scale = 1;
  HeaderRow header = HeaderRow::automatic;
  Delimiter delimiter = Delimiter::automatic;
  // Where the mapping came from, for errors: a mapping file and the line of each key in it, or
  // "command line" (line 0).
  std::string origin = "command line";
  std::map<std::string, int> lines;
};

// Reads a mapping file (the keys above, units under `units: {time, angle, torque_scale}`; an
// `imported:` record, as import.yaml has, is ignored, so import.yaml can be reused). Throws
// DataError(file, line) on bad YAML, an unknown key or value.
ImportMapping read_import_mapping(const std::filesystem::path& yaml);
// The mapping as a mapping file reads it back.
std::string import_mapping_yaml(const ImportMapping& mapping);

// The robot the logs are of.
struct ImportTarget {
  std::string robot;
  std::vector<std::string> joints;   // names, in the model's order
  std::vector<bool> prismatic;       // per joint (empty: all revolute)
  std::vector<double> lower, upper;  // position limits per joint, rad or m (empty: not checked)
  std::vector<double> effort;        // torque (force) limits per joint, N m or N (empty or 0: not checked)
};

// The target of a compiled model: its joints' names, types and position limits.
ImportTarget import_target(const std::string& robot, const std::vector<JointInfo>& joints);

// Settings given by name over a mapping (dynid import's options, symoro.import_logs' keywords);
// "" (0 for torque_scale) leaves a setting as the mapping has it.
struct MappingSettings {
  std::string time, q, qd, tau, q_ref, qd_ref, qdd_ref;  // column selectors
  std::string time_unit;                                 // s | ms | us | ns
  std::string angle;                                     // rad | deg
  std::string header;                                    // auto | yes | no
  std::string delimiter;                                 // auto | comma | semicolon | whitespace
  double torque_scale = 0;
};
// std::invalid_argument naming the setting and its choices for a word not among them.
void apply_settings(ImportMapping& mapping, const MappingSettings& settings);

// How a ROS 2 bag's sensor_msgs/msg/JointState messages become a log (io/import_bag.hpp).
enum class StampSource { header, receive };  // header.stamp, or the recorder's receive time
enum class EffortKind { torque, current };   // effort is joint torque, or motor current (A)
struct BagSettings {
  std::string topic = "/joint_states";
  StampSource stamp = StampSource::header;
  EffortKind effort = EffortKind::torque;
  std::vector<double> torque_constants;  // N m/A per joint, for EffortKind::current
};

// One input file, converted.
struct ImportedLog {
  std::filesystem::path input;
  Log log;                                     // meta: robot, trajectory (the file's stem), source "robot",
                                               // sample_time (median interval to the us), velocity
  int rows = 0;                                // data rows in the input
  std::vector<int> lines;                      // 1-based input line of each written row
  std::vector<int> stale_lines;                // 1-based input lines of stale rows (kept)
  std::vector<int> duplicate_lines;            // 1-based input lines of duplicates (dropped)
  std::map<std::string, std::string> columns;  // log column -> input column ("q1" -> "pos_1 (column 3)")
  std::vector<std::string> remarks;            // what the import decided and the user should know (bags)
};

// Reads and converts one input file. Throws DataError as described above; a mapping that does
// not fit the target (another number of columns than joints) names the mapping's origin.
ImportedLog import_log(const std::filesystem::path& input, const ImportMapping& mapping, const ImportTarget& target);

// Unit plausibility (a unit declared wrong: deg read as rad, ms read as s): throws DataError
// naming the file, the evidence and --allow-implausible, which skips the check, when
//   a joint's position is beyond a limit by more than max(0.5 rad, half the joint's range)
//     (revolute; prismatic: max(0.05 m, half the range)); joints without finite limits pass;
//   the median time step is outside [0.1 ms, 0.5 s];
//   a gap between two rows exceeds 1 s and 1000 median steps;
//   the angles are declared in deg but every revolute joint stays within +-2 pi and moves less
//     than 2 pi as written (radians declared as degrees);
//   a measured velocity whose integral over the stamps is not the position's change
//     (velocity_agreement: a moving joint's scale outside [0.8, 1.25], or its mismatch over 0.5):
//     a velocity unit, a time unit or a column mapped wrong.
// import_dataset calls it on every input unless DatasetImport::allow_implausible.
void check_plausible(const ImportedLog& imported, const ImportMapping& mapping, const ImportTarget& target);

// How a log's measured velocity agrees with its stamps and positions, per joint: over windows of
// about `span` s (5 to 100 rows), the position's change against the trapezoid integral of the
// logged velocity over the same stamps. scale = sum(dq I) / sum(I^2) is 1 when the three agree; a velocity in deg/s
// beside radians gives 1/57, stamps read 2 % too close together 0.98 (Gaz et al.'s Panda export:
// 0.9997-1.0005 on its stamps, 1.008-1.038 read 1 ms apart). Windows across a wrap or a jump
// (|dq| > 3.14) are left out; a joint that barely moves (RMS change per window under 1e-3) has
// NaN. mismatch: RMS of dq - scale I over RMS of dq (0: the velocity follows the position).
struct VelocityAgreement {
  Eigen::VectorXd scale, mismatch;  // per joint
  int window = 0, windows = 0;
};
VelocityAgreement velocity_agreement(const Log& log, double span = 0.1);

// The velocity written when the input has none: per joint, the derivative of the parabola
// through each row and its neighbours (second order on irregular stamps; the end rows use the
// end three). Rows flagged in `skip` (stale) take no part and repeat the previous row's value.
Eigen::MatrixXd differentiate_positions(const Eigen::VectorXd& time, const Eigen::MatrixXd& q,
                                        const std::vector<bool>& skip);

// The median stamp interval rounded to the nearest microsecond (the sidecar's sample_time).
// Throws DataError(source, 0) with fewer than 2 stamps or a median under 0.5 us.
double median_sample_time(const Eigen::VectorXd& time, const std::string& source);

struct ImportInput {
  std::filesystem::path file;
  std::string name;      // run name ("" : the file's stem)
  bool heldout = false;  // the whole file is held out (family V)
};

struct DatasetImport {
  ImportTarget target;
  ImportMapping mapping;  // for text inputs
  BagSettings bag;        // for ROS 2 bags (an .mcap file or a bag folder: is_bag)
  std::vector<ImportInput> inputs;
  // Fraction of each run (not held out as a whole) used for fitting, by time: the first
  // `split` of its duration; the rest is a second run <name>_heldout. 0: no split.
  double split = 0;
  // Import values check_plausible refuses (--allow-implausible).
  bool allow_implausible = false;
};

struct DatasetImportResult {
  std::vector<ImportedLog> logs;
  std::filesystem::path dataset;  // the dataset.yaml written
  struct Run {
    std::string trajectory, family;
    std::filesystem::path file;
    double window_start, window_end;
  };
  std::vector<Run> runs;
};

// Imports every input into `out` (created): <name>.csv + .meta.yaml per input, import.yaml
// (the mapping and what each input gave), dataset.yaml last. Every input is read and checked
// (check_plausible; a split leaving a part with fewer than 4 samples is refused) before anything
// is written, and no existing file is ever replaced (DataError naming it).
DatasetImportResult import_dataset(const std::filesystem::path& out, const DatasetImport& import);

}  // namespace symoro::io
