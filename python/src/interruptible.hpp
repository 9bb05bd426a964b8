// A long C++ job run from Python so that Ctrl-C stops it cleanly (identify, diagnose): the job
// runs in a thread of its own while the calling thread waits with the GIL released.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>

#include <pybind11/pybind11.h>

namespace symoro::python {

namespace py = pybind11;

// Runs `work` in a thread of its own; this thread waits with the GIL released, checking every
// 50 ms for a signal. On KeyboardInterrupt (or another signal handler's exception) it sets
// `stop`, waits for `work` to end, and raises that exception.
template <class Work>
inline void run_interruptible(std::atomic<bool>& stop, Work&& work) {
  std::mutex m;
  std::condition_variable cv;
  bool done = false;
  std::exception_ptr error;
  std::thread t([&] {
    try {
      work();
    } catch (...) {
      error = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(m);
    done = true;
    cv.notify_all();
  });
  bool interrupted = false;
  for (;;) {
    {
      py::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(m);
      if (cv.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; })) break;
    }
    if (!interrupted && PyErr_CheckSignals() != 0) {
      interrupted = true;  // the exception stays set until the study has stopped
      stop = true;
    }
  }
  {
    py::gil_scoped_release release;
    t.join();
  }
  if (interrupted) throw py::error_already_set();
  if (error) std::rethrow_exception(error);
}

}  // namespace symoro::python
