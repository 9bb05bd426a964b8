// The measured-data log: one CSV file with a header row and a metadata sidecar.
//
//   <name>.csv        time,q1..qn,qd1..qdn,tau1..taun[,q_ref1..,qd_ref1..,qdd_ref1..]
//   <name>.meta.yaml  format: symoro-log 1, robot, trajectory, trial, seed, source,
//                     sample_time, samples (the CSV's row count), joints, units, notes,
//                     velocity (optional: measured | differentiated; absent = measured)
//
// Columns may come in any order; they are matched by name. The three reference groups come
// together or not at all. Units are SI: s, rad (m for a prismatic joint), rad/s, N m (N); the
// sidecar's units map says so for human readers, and the reader rejects any other unit. The
// joint count n is the length of the sidecar's joint list; the CSV must have exactly the
// columns for n joints.
//
// The reader rejects, with file and 1-based line: a missing, duplicate or unknown column, a
// partial reference group, a row with the wrong number of fields, a blank line, an empty
// field, a field that is not a finite number (NaN, inf, text), time that does not increase
// strictly, a log without rows, a row count that differs from the sidecar's (a truncated
// CSV), a last line without its newline (the writers always end one: the file was cut), and a
// missing or malformed sidecar (bad YAML, a missing, unknown or ill-typed key, an unknown
// format version, source or unit, an empty or repeated joint name). It never drops or repairs
// a sample: what the file holds is what the Log holds. "\r\n" line ends, spaces around fields
// and a UTF-8 byte order mark are accepted.
//
// A reference file (metadata source: "reference", written for each designed trajectory) holds
// time and the three reference groups only; q, qd and tau then have 0 columns (and as many
// rows as samples when read).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace symoro::io {

// Where a log's qd columns come from. The format requires them; a log imported without
// velocities has them differentiated from q, which preprocessing must not take for a measurement.
enum class Velocity { measured, differentiated };

struct LogMetadata {
  std::string robot;                       // robots/<robot>
  std::string trajectory;                  // e.g. "AG02"
  int trial = 0;                           // repetition number, 1-based (0: not a repeated trial)
  std::uint64_t seed = 0;                  // the twin's seed (0 for a real arm)
  std::string source;                      // "twin", "robot" or "reference"
  double sample_time = 0;                  // nominal control period, s (e.g. 0.001)
  std::vector<std::string> joints;         // joint names, in column order 1..n
  std::string notes;                       // free text (e.g. the twin configuration used)
  Velocity velocity = Velocity::measured;  // sidecar key written only when differentiated
};

// Samples are rows: time(k), q(k, j). Reference matrices have 0 columns when the log has none.
struct Log {
  LogMetadata meta;
  Eigen::VectorXd time;        // s
  Eigen::MatrixXd q, qd, tau;  // samples x joints
  Eigen::MatrixXd q_ref, qd_ref, qdd_ref;
  // A window of a longer file (a dataset run's window, io::read_run_log): that file as read, and
  // the row of it where this log's rows begin. Preprocessing filters the whole file and keeps
  // this log's samples, so that a window cut in mid-motion has no filter edge (preprocess.hpp).
  // Null for a whole file.
  std::shared_ptr<const Log> file;
  Eigen::Index file_row = 0;
  int samples() const { return static_cast<int>(time.size()); }
  int joints() const { return static_cast<int>(q.cols()); }  // 0 in a reference file
  bool has_references() const { return q_ref.cols() > 0; }
};

// The sidecar of "dir/name.csv" is "dir/name.meta.yaml".
std::filesystem::path metadata_path(const std::filesystem::path& csv);

// Checks what write_log requires of a Log: a known source, at least one sample, a non-empty
// robot name, unique non-empty joint names, every matrix samples x meta.joints.size() (q, qd
// and tau 0 columns in a reference file; the reference groups all present or all absent,
// required in a reference file), finite values, strictly increasing time and a positive finite
// sample_time. Throws DataError(file, 0, the first problem found).
void validate_log(const Log& log, const std::string& file = "log");

// Writes the CSV and its sidecar atomically (each file written to a temporary, then renamed;
// the sidecar last, so a sidecar always describes a complete CSV). Numbers are written so that
// they read back bit for bit. Throws DataError when the Log is inconsistent (sizes, NaN,
// non-increasing time) or a file cannot be written.
void write_log(const std::filesystem::path& csv, const Log& log);

// Reads and validates a CSV and its sidecar. Throws DataError naming the file and line.
Log read_log(const std::filesystem::path& csv);

// Reads and validates the sidecar of `csv` only (cheap: for listing logs without loading
// them). Throws DataError naming the sidecar and line.
LogMetadata read_log_metadata(const std::filesystem::path& csv);

}  // namespace symoro::io
