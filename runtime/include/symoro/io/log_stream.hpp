// A log written while it is recorded (a control loop's run): the same files as write_log (CSV +
// .meta.yaml sidecar, log.hpp), streamed. append() copies one row into a lock-free
// single-producer single-consumer queue (boost::lockfree::spsc_queue): it never does I/O,
// allocates, takes a lock or waits, so a real-time loop can call it. A background thread drains
// the queue every `flush_every` and then rewrites the sidecar (atomically) with the row count
// written so far, so that the files on disk are always a log read_log accepts, up to the last
// flush. close() (also from the destructor) writes the rest and the final sidecar (with the
// notes set last). append() and close() belong to one thread (the producer); flush(),
// set_notes() and the counters may be called from any.
//
//   io::LogStream log("run.csv", meta, /*references=*/true);
//   log.append(t, q, qd, tau, q_ref, qd_ref, qdd_ref);   // in the loop, n values each
//   log.set_notes("...timing...");
//   log.close();
//
// Rows must be finite with strictly increasing time (as write_log requires); a row that is not
// is dropped and counted (rejected()), so a log on disk stays readable. When the writer falls
// behind by `capacity` rows, further rows are dropped and counted (overflowed()).
#pragma once

#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <boost/lockfree/spsc_queue.hpp>

#include "symoro/io/log.hpp"

namespace symoro::io {

class LogStream {
 public:
  LogStream(std::filesystem::path csv, LogMetadata meta, bool references,
            std::chrono::milliseconds flush_every = std::chrono::milliseconds(100), std::size_t capacity = 1 << 14);
  ~LogStream();
  LogStream(const LogStream&) = delete;
  LogStream& operator=(const LogStream&) = delete;

  // One row; each pointer holds joints() values (the reference ones are ignored without
  // references). False when the row was dropped (not finite, time not increasing, overflow).
  bool append(double time, const double* q, const double* qd, const double* tau, const double* q_ref = nullptr,
              const double* qd_ref = nullptr, const double* qdd_ref = nullptr);
  // Notes for the sidecar (written at the next flush and by close()).
  void set_notes(std::string notes);
  // Writes what is buffered now and waits until it is on disk (CSV and sidecar).
  void flush();
  // Writes everything, the final sidecar, stops the writer; idempotent. Throws DataError when a
  // file could not be written (also reported by the destructor to stderr, never thrown there).
  void close();

  const std::filesystem::path& path() const { return csv_; }
  int joints() const { return n_; }
  std::int64_t appended() const;  // rows accepted by append()
  std::int64_t written() const;   // rows on disk (and in the sidecar)
  std::int64_t rejected() const;
  std::int64_t overflowed() const;
  // A write that failed (a full disk): the CSV then ends on its last whole row, the sidecar
  // counts those rows and its notes say "LOG INCOMPLETE: <the reason>", the rows appended later
  // are lost (counted) and close() throws with the reason. Any thread may ask.
  bool failed() const;
  std::string error() const;  // the first I/O error ("" when none)
  std::int64_t lost() const;  // rows accepted by append() that never reached the file

 private:
  void run();
  std::size_t drain();  // pops whole rows into rows_ and writes them (the writer thread / close())
  void write_out(const std::vector<double>& rows, std::size_t count);
  void write_sidecar(std::int64_t samples);
  std::string sidecar_text(std::int64_t samples) const;
  void write_incomplete_sidecar();  // atomically, else in place when there is no room for a new one

  std::filesystem::path csv_;
  LogMetadata meta_;
  bool references_;
  int n_;
  std::size_t width_;  // values per row
  std::chrono::milliseconds flush_every_;
  std::size_t capacity_;

  // The producer's side (append): its queue end, its row buffer, the last time it took.
  boost::lockfree::spsc_queue<double> queue_;  // whole rows of width_ values
  std::vector<double> row_;
  double last_time_ = 0;
  bool has_last_ = false;
  std::atomic<bool> closed_{false};
  std::atomic<std::int64_t> appended_{0}, rejected_{0}, overflowed_{0}, written_{0}, lost_{0};
  std::atomic<bool> failed_{false};

  // Between the writer thread and flush()/set_notes()/close() (never the producer's path).
  mutable std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::uint64_t flush_requests_ = 0, flushes_done_ = 0;
  bool stop_ = false;
  std::string notes_;
  std::string error_;  // first I/O error of the writer
  int fd_ = -1;
  off_t whole_ = 0;           // the CSV's size up to its last whole row (the writer's)
  std::vector<double> rows_;  // the writer's batch
  std::string text_;          // the writer's formatting buffer
  std::thread thread_;
};

}  // namespace symoro::io
