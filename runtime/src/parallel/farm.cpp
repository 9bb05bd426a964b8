#include "symoro/parallel/farm.hpp"

#include <sched.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <system_error>
#include <thread>

#include <fmt/format.h>

#include "task.hpp"

namespace symoro::parallel {

namespace detail {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The pipe from an isolated task's process: messages of a kind ('R' a result, 'F' the task's
// failure), a 64-bit length and the text.
bool write_all(int fd, const char* p, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    p += w;
    n -= static_cast<std::size_t>(w);
  }
  return true;
}

// Reads exactly n bytes; false at end of file (or an error) before them.
bool read_all(int fd, char* p, std::size_t n) {
  while (n > 0) {
    const ssize_t r = ::read(fd, p, n);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return false;
    p += r;
    n -= static_cast<std::size_t>(r);
  }
  return true;
}

void send(int fd, char kind, const std::string& text) {
  char head[9];
  head[0] = kind;
  const std::uint64_t n = text.size();
  std::memcpy(head + 1, &n, sizeof n);
  if (!write_all(fd, head, sizeof head) || !write_all(fd, text.data(), text.size())) ::_exit(3);  // the parent is gone
}

// The task's process: runs it, sends its results and its failure, flushes what it printed and
// ends without running the parent's exit handlers (_exit).
[[noreturn]] void run_child(const Farm& farm, const std::string& task, int out) {
  try {
    farm.work(task, [out](const std::string& r) { send(out, 'R', r); });
  } catch (const std::exception& e) {
    send(out, 'F', e.what());
  } catch (...) {
    send(out, 'F', "an exception that is not a std::exception");
  }
  std::fflush(nullptr);
  ::_exit(0);
}

std::string describe_death(int status) {
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    return fmt::format("the task's process was killed by signal {} ({}){}", sig, strsignal(sig),
                       sig == SIGKILL ? "; out of memory? (the kernel's OOM killer sends SIGKILL)" : "");
  }
  return fmt::format("the task's process exited with code {} before it finished", WEXITSTATUS(status));
}

// Forks are serialized, and the parent closes its end of each pipe before the next fork: a later
// task's process then holds no write end of an earlier task's pipe, whose reader would otherwise
// never see the end of file of a process that died.
std::mutex fork_mutex;

TaskEnd run_isolated(const Farm& farm, const std::string& task, const std::function<void(const std::string&)>& result) {
  TaskEnd end;
  int fd[2];
  pid_t pid;
  {
    std::lock_guard<std::mutex> lock(fork_mutex);
    if (::pipe(fd) != 0) throw std::system_error(errno, std::generic_category(), "pipe for a task's process");
    std::fflush(nullptr);  // else the child would print again what the parent had buffered
    const pid_t parent = ::getpid();
    pid = ::fork();
    if (pid < 0) {
      const int e = errno;
      ::close(fd[0]);
      ::close(fd[1]);
      throw std::system_error(e, std::generic_category(), "fork of a task's process");
    }
    if (pid == 0) {
      // A task whose rank died (killed, lost with its node) is of no use: it dies too, instead of
      // computing on, orphaned, beside whatever runs next.
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (::getppid() != parent) ::_exit(4);
      ::close(fd[0]);
      run_child(farm, task, fd[1]);
    }
    ::close(fd[1]);
  }
  bool complete = true;  // every message whole
  for (;;) {
    char head[9];
    if (!read_all(fd[0], head, sizeof head)) break;
    std::uint64_t n;
    std::memcpy(&n, head + 1, sizeof n);
    std::string text(n, '\0');
    if (!read_all(fd[0], text.data(), n)) {
      complete = false;
      break;
    }
    if (head[0] == 'R') {
      result(text);
    } else {
      end.failed = true;
      end.failure = text;
    }
  }
  ::close(fd[0]);
  int status = 0;
  rusage usage{};
  while (::wait4(pid, &status, 0, &usage) < 0 && errno == EINTR) {
  }
  end.peak_memory_mb = usage.ru_maxrss / 1024.0;
  if (!(WIFEXITED(status) && WEXITSTATUS(status) == 0) || !complete) {
    end.failed = true;
    end.failure = describe_death(status);
  }
  return end;
}

}  // namespace

TaskEnd run_task(const Farm& farm, const std::string& task, bool isolate,
                 const std::function<void(const std::string&)>& result) {
  const auto t0 = std::chrono::steady_clock::now();
  TaskEnd end;
  try {
    if (isolate) {
      end = run_isolated(farm, task, result);
    } else {
      farm.work(task, result);
    }
  } catch (const std::exception& e) {
    end.failed = true;
    end.failure = e.what();
  }
  end.wall = seconds_since(t0);
  return end;
}

int worker_count(const FarmOptions& options, int ranks_on_this_machine) {
  if (options.workers > 0) return options.workers;
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  // A process bound to fewer cores (mpirun binds each rank to a core when it starts two or
  // fewer; Slurm's --cpus-per-task) gets as many workers as it may use cores.
  cpu_set_t mask;
  CPU_ZERO(&mask);
  if (::sched_getaffinity(0, sizeof mask, &mask) == 0 && CPU_COUNT(&mask) < cores) return std::max(1, CPU_COUNT(&mask));
  return std::max(1, cores / std::max(1, ranks_on_this_machine));
}

}  // namespace detail

namespace {

FarmSummary run_local(const std::vector<std::string>& tasks, const Farm& farm, const FarmOptions& options) {
  FarmSummary summary;
  summary.workers = std::min(detail::worker_count(options, 1), std::max(1, static_cast<int>(tasks.size())));
  summary.tasks.resize(tasks.size());
  std::mutex m;          // one callback at a time
  std::size_t next = 0;  // under m
  auto worker = [&] {
    for (;;) {
      std::size_t i = 0;
      {
        std::lock_guard<std::mutex> lock(m);
        if (!summary.stopped && next < tasks.size() && farm.stop && farm.stop()) summary.stopped = true;
        if (summary.stopped || next >= tasks.size()) return;
        i = next++;
      }
      TaskEnd e = detail::run_task(farm, tasks[i], options.isolate, [&](const std::string& r) {
        std::lock_guard<std::mutex> lock(m);
        if (farm.on_result) farm.on_result(i, r);
      });
      e.task = i;
      std::lock_guard<std::mutex> lock(m);
      summary.tasks[i] = e;
      if (farm.on_end) farm.on_end(e);
    }
  };
  std::vector<std::thread> pool;
  for (int w = 0; w < summary.workers; ++w) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  for (std::size_t i = next; i < tasks.size(); ++i) summary.tasks[i] = TaskEnd{i, 0, true, "stopped"};
  return summary;
}

}  // namespace

FarmSummary run_farm(const std::vector<std::string>& tasks, const Farm& farm, const FarmOptions& options) {
  if (place().ranks > 1) return detail::run_farm_mpi(tasks, farm, options);
  return run_local(tasks, farm, options);
}

}  // namespace symoro::parallel
