// Writing a log: the CSV built row by row in a memory buffer (shortest round-trip numbers,
// no stream formatting), then the sidecar, each through an AtomicFile.
#include <algorithm>
#include <string>
#include <vector>

#include "log_columns.hpp"
#include "log_sidecar.hpp"
#include "symoro/io/atomic_file.hpp"
#include "symoro/io/log.hpp"
#include "symoro/io/number_text.hpp"

namespace symoro::io {

using detail::Group;

std::filesystem::path metadata_path(const std::filesystem::path& csv) {
  std::filesystem::path sidecar = csv;
  sidecar.replace_extension(".meta.yaml");
  return sidecar;
}

namespace {

// One column of the CSV: where its values are (column-major: consecutive samples adjacent).
struct ColumnSource {
  std::string name;
  const double* values;
};

std::vector<ColumnSource> csv_columns(const Log& log) {
  std::vector<ColumnSource> columns;
  for (Group g : detail::groups_of(log)) {
    if (g == Group::time) {
      columns.push_back({"time", log.time.data()});
      continue;
    }
    const Eigen::MatrixXd& m = detail::group_matrix(log, g);
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      columns.push_back({detail::column_name({g, static_cast<int>(j)}), m.col(j).data()});
  }
  return columns;
}

void write_csv(const std::filesystem::path& csv, const Log& log) {
  const std::vector<ColumnSource> columns = csv_columns(log);
  AtomicFile file(csv);
  std::string header;
  for (const ColumnSource& c : columns) header += (header.empty() ? "" : ",") + c.name;
  header += '\n';
  file.stream().write(header.data(), static_cast<std::streamsize>(header.size()));

  // Rows go into a fixed buffer handed to the stream in large blocks: the file is written at
  // the speed of number formatting, whatever the log's size.
  const std::size_t row_room = columns.size() * (max_number_chars + 1) + 1;
  std::vector<char> buffer(std::max<std::size_t>(1 << 20, 2 * row_room));
  char* const begin = buffer.data();
  char* const flush_at = begin + buffer.size() - row_room;
  char* out = begin;
  const Eigen::Index samples = log.time.size();
  for (Eigen::Index k = 0; k < samples; ++k) {
    for (const ColumnSource& c : columns) {
      out = to_text(out, c.values[k]);
      *out++ = ',';
    }
    out[-1] = '\n';
    if (out >= flush_at) {
      file.stream().write(begin, out - begin);
      out = begin;
    }
  }
  file.stream().write(begin, out - begin);
  file.commit();
}

}  // namespace

void write_log(const std::filesystem::path& csv, const Log& log) {
  validate_log(log, csv.string());
  const std::filesystem::path sidecar = metadata_path(csv);
  const std::string sidecar_content = detail::sidecar_text(log, sidecar.string());
  write_csv(csv, log);
  // Last, so that a sidecar (with its sample count) never describes a CSV not yet in place.
  write_file_atomically(sidecar, sidecar_content);
}

}  // namespace symoro::io
