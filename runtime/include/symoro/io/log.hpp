// The measured-data log: one CSV file with a header row and a metadata sidecar.
//
//   <name>.csv        time,q1..qn,qd1..qdn,tau1..taun[,q_ref1..,qd_ref1..,qdd_ref1..]
//   <name>.meta.yaml  robot, trajectory, trial, seed, source, sample_time, joints, units
//
// Columns may come in any order; they are matched by name. Units are SI: s, rad (m for a
// prismatic joint), rad/s, N m (N). The reader rejects, with file and line: a missing or
// duplicate column, a partial group (q_ref for some joints only), a row with the wrong number
// of fields, a field that is not a finite number (NaN, inf, text), time that does not increase
// strictly, an empty log, and metadata that disagrees with the CSV (robot, joint count). It
// never drops or repairs a sample: what the file holds is what the Log holds.
//
// A reference file (metadata source: "reference", written for each designed trajectory) holds
// time and the three reference groups only; q, qd and tau then have 0 columns.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace symoro::io {

struct LogMetadata {
  std::string robot;        // robots/<robot>
  std::string trajectory;   // e.g. "AG02"
  int trial = 0;            // repetition number, 1-based (0: not a repeated trial)
  std::uint64_t seed = 0;   // the twin's seed (0 for a real arm)
  std::string source;       // "twin" or "robot"
  double sample_time = 0;   // nominal control period, s (e.g. 0.001)
  std::vector<std::string> joints;  // joint names, in column order 1..n
  std::string notes;        // free text (e.g. the twin configuration used)
};

// Samples are rows: time(k), q(k, j). Reference matrices have 0 columns when the log has none.
struct Log {
  LogMetadata meta;
  Eigen::VectorXd time;                 // s
  Eigen::MatrixXd q, qd, tau;           // samples x joints
  Eigen::MatrixXd q_ref, qd_ref, qdd_ref;
  int samples() const { return static_cast<int>(time.size()); }
  int joints() const { return static_cast<int>(q.cols()); }
  bool has_references() const { return q_ref.cols() > 0; }
};

// The sidecar of "dir/name.csv" is "dir/name.meta.yaml".
std::filesystem::path metadata_path(const std::filesystem::path& csv);

// Writes the CSV and its sidecar atomically (each file written to a temporary, then renamed;
// the sidecar last, so a sidecar always describes a complete CSV). Numbers are written so that
// they read back bit for bit. Throws DataError when the Log is inconsistent (sizes, NaN,
// non-increasing time) or a file cannot be written.
void write_log(const std::filesystem::path& csv, const Log& log);

// Reads and validates a CSV and its sidecar. Throws DataError naming the file and line.
Log read_log(const std::filesystem::path& csv);

}  // namespace symoro::io
