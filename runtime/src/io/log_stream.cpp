// The streaming log writer: rows into a lock-free queue, a thread that drains, formats and
// appends them to the CSV, then rewrites the sidecar with the count on disk.
#include "symoro/io/log_stream.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <fmt/format.h>

#include "log_columns.hpp"
#include "log_sidecar.hpp"
#include "symoro/error.hpp"
#include "symoro/io/atomic_file.hpp"
#include "symoro/io/number_text.hpp"

namespace symoro::io {

using detail::Group;

LogStream::LogStream(std::filesystem::path csv, LogMetadata meta, bool references,
                     std::chrono::milliseconds flush_every, std::size_t capacity)
    : csv_(std::move(csv)),
      meta_(std::move(meta)),
      references_(references),
      n_(static_cast<int>(meta_.joints.size())),
      width_(1 + static_cast<std::size_t>(n_) * (references ? 6 : 3)),
      flush_every_(flush_every),
      capacity_(capacity < 16 ? 16 : capacity),
      queue_(capacity_ * width_) {
  if (n_ == 0) throw DataError(csv_.string(), 0, "a streamed log needs joint names");
  if (meta_.source != "twin" && meta_.source != "robot")
    throw DataError(csv_.string(), 0, "a streamed log's source is 'robot' or 'twin', not '" + meta_.source + "'");
  if (!(meta_.sample_time > 0) || !std::isfinite(meta_.sample_time))
    throw DataError(csv_.string(), 0, "a streamed log needs a positive sample_time");
  row_.resize(width_);
  rows_.resize(capacity_ * width_);
  text_.reserve(1 << 20);
  notes_ = meta_.notes;
  if (!csv_.parent_path().empty()) std::filesystem::create_directories(csv_.parent_path());
  fd_ = ::open(csv_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw DataError(csv_.string(), 0, std::string("cannot write the log: ") + std::strerror(errno));
  std::string header = "time";
  const Group groups[] = {Group::q, Group::qd, Group::tau, Group::q_ref, Group::qd_ref, Group::qdd_ref};
  for (int g = 0; g < (references_ ? 6 : 3); ++g)
    for (int j = 0; j < n_; ++j) header += "," + detail::column_name({groups[g], j});
  header += '\n';
  if (::write(fd_, header.data(), header.size()) != static_cast<ssize_t>(header.size())) {
    const int e = errno;
    ::close(fd_);
    throw DataError(csv_.string(), 0, std::string("cannot write the log: ") + std::strerror(e));
  }
  whole_ = static_cast<off_t>(header.size());
  write_sidecar(0);
  thread_ = std::thread([this] { run(); });
}

LogStream::~LogStream() {
  try {
    close();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
  }
}

bool LogStream::append(double time, const double* q, const double* qd, const double* tau, const double* q_ref,
                       const double* qd_ref, const double* qdd_ref) {
  // Wait-free: no lock, no allocation, no I/O (the producer owns row_, last_time_, has_last_).
  const double* groups[] = {q, qd, tau, q_ref, qd_ref, qdd_ref};
  const int count = references_ ? 6 : 3;
  bool finite = std::isfinite(time);
  for (int g = 0; g < count && finite; ++g) {
    if (!groups[g]) {
      finite = false;
      break;
    }
    for (int j = 0; j < n_; ++j) finite = finite && std::isfinite(groups[g][j]);
  }
  if (closed_.load(std::memory_order_acquire) || !finite || (has_last_ && !(time > last_time_))) {
    rejected_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  if (queue_.write_available() < width_) {
    overflowed_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  double* out = row_.data();
  *out++ = time;
  for (int g = 0; g < count; ++g)
    for (int j = 0; j < n_; ++j) *out++ = groups[g][j];
  queue_.push(row_.data(), width_);  // one publication: the writer sees whole rows
  appended_.fetch_add(1, std::memory_order_relaxed);
  last_time_ = time;
  has_last_ = true;
  return true;
}

void LogStream::set_notes(std::string notes) {
  std::lock_guard<std::mutex> lock(mutex_);
  notes_ = std::move(notes);
}

void LogStream::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    const std::uint64_t requested = flush_requests_;
    wake_.wait_for(lock, flush_every_, [&] { return stop_ || flush_requests_ != requested; });
    const std::uint64_t serving = flush_requests_;
    const bool stopping = stop_;
    lock.unlock();
    const std::size_t rows = drain();
    if (rows == 0 && serving != flushes_done_) write_out(rows_, 0);  // a flush rewrites the sidecar (its notes)
    lock.lock();
    flushes_done_ = serving;
    done_.notify_all();
    if (stopping) return;
  }
}

std::size_t LogStream::drain() {
  std::size_t total = 0;
  for (;;) {
    const std::size_t available = queue_.read_available() / width_ * width_;
    if (available == 0) return total;
    const std::size_t take = std::min(available, rows_.size());
    const std::size_t got = queue_.pop(rows_.data(), take);
    write_out(rows_, got / width_);
    total += got / width_;
  }
}

void LogStream::write_out(const std::vector<double>& rows, std::size_t count) {
  if (failed_.load(std::memory_order_relaxed)) {  // the file ends on its last whole row: no more
    lost_.fetch_add(static_cast<std::int64_t>(count), std::memory_order_relaxed);
    return;
  }
  text_.clear();
  char number[max_number_chars];
  for (std::size_t r = 0; r < count; ++r) {
    const double* row = rows.data() + r * width_;
    for (std::size_t c = 0; c < width_; ++c) {
      char* end = to_text(number, row[c]);
      text_.append(number, end);
      text_ += c + 1 < width_ ? ',' : '\n';
    }
  }
  std::size_t done = 0;
  while (done < text_.size()) {
    const ssize_t w = ::write(fd_, text_.data() + done, text_.size() - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      // A full disk (or a file size limit) stops the log where its last whole row ends: the
      // part of this batch that got out is cut off, the rest of the run's rows are counted as
      // lost, and the sidecar says the log is incomplete.
      const int e = w < 0 ? errno : ENOSPC;
      const bool cut = ::ftruncate(fd_, whole_) == 0;
      (void)::lseek(fd_, whole_, SEEK_SET);
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (error_.empty()) error_ = std::string("cannot write the log: ") + std::strerror(e);
        if (!cut) error_ += "; and cannot cut its last partial row";
      }
      lost_.fetch_add(static_cast<std::int64_t>(count), std::memory_order_relaxed);
      failed_.store(true, std::memory_order_release);
      write_incomplete_sidecar();
      return;
    }
    done += static_cast<std::size_t>(w);
  }
  whole_ += static_cast<off_t>(text_.size());
  const std::int64_t total = written_.fetch_add(static_cast<std::int64_t>(count)) + static_cast<std::int64_t>(count);
  try {
    write_sidecar(total);
  } catch (const std::exception& e) {
    // No room for the new sidecar (a full disk takes it before the CSV's next block): the log
    // stops here too, its CSV whole, its sidecar rewritten in place to say so.
    {
      std::lock_guard<std::mutex> lock(mutex_);
      std::string why = e.what();  // "<sidecar>: error: writing failed: <reason>; the previous file ..."
      why = why.substr(0, why.find("; the previous file"));
      if (error_.empty()) error_ = "cannot write the log's sidecar: " + why;
    }
    failed_.store(true, std::memory_order_release);
    write_incomplete_sidecar();
  }
}

void LogStream::write_incomplete_sidecar() {
  try {
    write_sidecar(written_.load());
  } catch (const std::exception&) {
    // The disk has no room for a new sidecar beside the old: rewrite the old one in place
    // (its blocks are there), so that it says what the CSV holds and why it ends.
    const std::filesystem::path sidecar = metadata_path(csv_);
    const std::string text = sidecar_text(written_.load());
    const int fd = ::open(sidecar.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd >= 0) {
      std::size_t done = 0;
      while (done < text.size()) {
        const ssize_t w = ::pwrite(fd, text.data() + done, text.size() - done, static_cast<off_t>(done));
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) break;
        done += static_cast<std::size_t>(w);
      }
      if (done == text.size()) (void)::ftruncate(fd, static_cast<off_t>(done));
      ::fsync(fd);
      ::close(fd);
    }
  }
}

std::string LogStream::sidecar_text(std::int64_t samples) const {
  Log log;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    log.meta = meta_;
    log.meta.notes = notes_;
    // A log cut short says so wherever it is read (read_log's notes, dynid's output).
    if (!error_.empty())
      log.meta.notes += fmt::format("{}LOG INCOMPLETE: {} after {} rows; the rows recorded after them are lost",
                                    log.meta.notes.empty() ? "" : "; ", error_, samples);
  }
  log.time = Eigen::VectorXd::Zero(samples);
  log.q.resize(0, n_);
  log.qd.resize(0, n_);
  log.tau.resize(0, n_);
  if (references_) {
    log.q_ref.resize(0, n_);
    log.qd_ref.resize(0, n_);
    log.qdd_ref.resize(0, n_);
  }
  return detail::sidecar_text(log, metadata_path(csv_).string());
}

void LogStream::write_sidecar(std::int64_t samples) {
  write_file_atomically(metadata_path(csv_), sidecar_text(samples));
}

void LogStream::flush() {
  std::unique_lock<std::mutex> lock(mutex_);
  if (closed_) return;
  const std::uint64_t id = ++flush_requests_;
  wake_.notify_one();
  done_.wait(lock, [&] { return flushes_done_ >= id; });
}

void LogStream::close() {
  if (closed_.exchange(true, std::memory_order_acq_rel)) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
  // The writer is gone: this thread is the queue's only consumer now. Rows appended after its
  // last pass are written, then the final sidecar.
  drain();
  if (failed_.load()) {
    write_incomplete_sidecar();
  } else {
    try {
      write_sidecar(written_.load());
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (error_.empty()) error_ = e.what();
    }
  }
  ::fsync(fd_);
  ::close(fd_);
  fd_ = -1;
  std::string error;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    error = error_;
  }
  if (!error.empty()) throw DataError(csv_.string(), 0, error);
}

std::int64_t LogStream::appended() const { return appended_.load(); }
std::int64_t LogStream::written() const { return written_.load(); }
std::int64_t LogStream::rejected() const { return rejected_.load(); }
std::int64_t LogStream::overflowed() const { return overflowed_.load(); }
std::int64_t LogStream::lost() const { return lost_.load(); }
bool LogStream::failed() const { return failed_.load(std::memory_order_acquire); }
std::string LogStream::error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return error_;
}

}  // namespace symoro::io
