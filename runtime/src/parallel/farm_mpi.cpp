// The job's place (MPI or one process) and the farm over MPI ranks.
//
// Rank 0's main thread is the coordinator: it answers task requests from the other ranks'
// worker threads, receives their results and ends, and runs the callbacks; rank 0's own worker
// threads take tasks from the same list without MPI. On the other ranks the worker threads
// share MPI under one mutex (MPI_THREAD_SERIALIZED). Waits poll (MPI_Iprobe, then a short
// sleep) so that an idle coordinator or worker does not take a core from the computation.
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "symoro/parallel/farm.hpp"
#include "task.hpp"

#ifdef SYMORO_WITH_MPI
#include <mpi.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <thread>
#include <utility>

#include <fmt/format.h>
#endif

namespace symoro::parallel {

#ifndef SYMORO_WITH_MPI

Place place() { return {}; }
bool mpi_built() { return false; }
void abort_job(int) {}
namespace detail {
FarmSummary run_farm_mpi(const std::vector<std::string>&, const Farm&, const FarmOptions&) {
  throw std::logic_error("run_farm_mpi: this build has no MPI");
}
}  // namespace detail

#else

namespace {

// Launched by an MPI launcher: Open MPI's mpirun, PMIx (srun --mpi=pmix, Open MPI 5), PMI
// (MPICH's hydra, srun --mpi=pmi2). Without one the binary runs as one process, as always.
bool launched() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(v)) return true;
  return false;
}

struct Session {
  Place place;
  int ranks_on_node = 1;
  bool active = false;
  bool lost_rank = false;  // MPI_Finalize would wait for it
  Session() {
    if (!launched()) return;
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
    active = true;
    if (provided < MPI_THREAD_SERIALIZED) {
      std::fprintf(stderr, "dynid: the MPI library gives no MPI_THREAD_SERIALIZED support\n");
      MPI_Abort(MPI_COMM_WORLD, 1);
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &place.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &place.ranks);
    MPI_Comm node;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
    MPI_Comm_size(node, &ranks_on_node);
    MPI_Comm_free(&node);
  }
  ~Session() {
    if (active && !lost_rank) MPI_Finalize();
  }
};

Session& session() {
  static Session s;
  return s;
}

constexpr int kRequest = 1, kResult = 2, kBye = 3, kBeat = 4, kEnd = 5, kTaskBase = 100;
constexpr auto kPoll = std::chrono::milliseconds(2);
constexpr auto kBeatEvery = std::chrono::seconds(1);
using Clock = std::chrono::steady_clock;

template <class T>
void put(std::string& b, T v) {
  b.append(reinterpret_cast<const char*>(&v), sizeof v);
}
template <class T>
T take(const std::string& b, std::size_t& at) {
  T v;
  std::memcpy(&v, b.data() + at, sizeof v);
  at += sizeof v;
  return v;
}

void send(const std::string& b, int dest, int tag) {
  MPI_Send(b.data(), static_cast<int>(b.size()), MPI_CHAR, dest, tag, MPI_COMM_WORLD);
}

// A message from `source` with `tag` (MPI_ANY_*: any), when one is there.
bool receive(int source, int tag, std::string& b, MPI_Status& st) {
  int flag = 0;
  MPI_Iprobe(source, tag, MPI_COMM_WORLD, &flag, &st);
  if (!flag) return false;
  int count = 0;
  MPI_Get_count(&st, MPI_CHAR, &count);
  b.assign(static_cast<std::size_t>(count), '\0');
  MPI_Recv(b.data(), count, MPI_CHAR, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return true;
}

std::string end_message(const TaskEnd& e) {
  std::string b(1, 'E');
  put<std::uint64_t>(b, e.task);
  put<std::int32_t>(b, e.failed);
  put<double>(b, e.wall);
  put<double>(b, e.peak_memory_mb);
  return b + e.failure;
}

// Rank 0: hands every task out, to this rank's workers and to the other ranks, and gathers
// their ends.
class Coordinator {
 public:
  Coordinator(const std::vector<std::string>& tasks, const Farm& farm, const FarmOptions& options)
      : tasks_(tasks), farm_(farm), options_(options), ranks_(session().place.ranks) {
    summary_.ranks = ranks_;
    summary_.workers = detail::worker_count(options, session().ranks_on_node);
    summary_.tasks.resize(tasks.size());
    heard_.assign(ranks_, Clock::now());
    spoke_.assign(ranks_, false);
    done_.assign(ranks_, false);
    lost_.assign(ranks_, false);
  }

  FarmSummary run() {
    std::vector<std::thread> pool;
    for (int w = 0; w < summary_.workers; ++w) pool.emplace_back([this] { work(); });
    std::string b;
    MPI_Status st;
    while (byes_ < ranks_ - 1) {
      if (!receive(MPI_ANY_SOURCE, MPI_ANY_TAG, b, st)) {
        fail_silent_ranks();
        std::this_thread::sleep_for(kPoll);
        continue;
      }
      heard_[st.MPI_SOURCE] = Clock::now();
      spoke_[st.MPI_SOURCE] = true;
      if (lost_[st.MPI_SOURCE]) continue;  // a rank taken as lost that was only slow: too late
      if (st.MPI_TAG == kRequest) {
        hand_out(b, st.MPI_SOURCE);
      } else if (st.MPI_TAG == kResult) {
        gather(b, st.MPI_SOURCE);
      } else if (st.MPI_TAG == kBye) {
        done_[st.MPI_SOURCE] = true;
        ++byes_;
      }
    }
    for (auto& t : pool) t.join();
    for (std::size_t i = next_; i < tasks_.size(); ++i) summary_.tasks[i] = TaskEnd{i, 0, true, "stopped"};
    // The end, to every rank still there, with whether one was lost: then no rank calls
    // MPI_Finalize, which would wait for the lost one forever.
    std::string end;
    put<std::int32_t>(end, session().lost_rank);
    for (int r = 1; r < ranks_; ++r)
      if (!lost_[r]) send(end, r, kEnd);
    return summary_;
  }

 private:
  // The next task, or -1: Farm::stop is asked before each, as the local farm does; once stopped,
  // every rank is told there is none.
  std::int64_t take_next() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!summary_.stopped && next_ < tasks_.size() && farm_.stop && farm_.stop()) summary_.stopped = true;
    return !summary_.stopped && next_ < tasks_.size() ? static_cast<std::int64_t>(next_++) : -1;
  }

  void ended(const TaskEnd& e) {
    std::lock_guard<std::mutex> lock(mutex_);
    summary_.tasks[e.task] = e;
    if (farm_.on_end) farm_.on_end(e);
  }

  // One of this rank's workers.
  void work() {
    for (std::int64_t i; (i = take_next()) >= 0;) {
      TaskEnd e = detail::run_task(farm_, tasks_[i], options_.isolate, [&](const std::string& r) {
        std::lock_guard<std::mutex> lock(mutex_);
        if (farm_.on_result) farm_.on_result(static_cast<std::size_t>(i), r);
      });
      e.task = static_cast<std::size_t>(i);
      ended(e);
    }
  }

  // Every other rank sends something at least every second (kBeat); one silent for longer than
  // rank_timeout is taken as lost (its process or node died; the job goes on only when the
  // launcher lets it, e.g. Open MPI's --mca orte_enable_recovery 1): its tasks in flight fail
  // with that reason and the others finish. Before its first message a rank gets ten times as
  // long: it may still be reading the study's inputs (a study's finished records, on a slow
  // shared file system).
  void fail_silent_ranks() {
    const auto now = Clock::now();
    const auto timeout = std::chrono::duration<double>(options_.rank_timeout);
    for (int r = 1; r < ranks_; ++r) {
      if (done_[r] || now - heard_[r] < (spoke_[r] ? 1 : 10) * timeout) continue;
      done_[r] = lost_[r] = true;
      ++byes_;
      session().lost_rank = true;
      for (auto t = running_.begin(); t != running_.end();) {
        if (t->second != r) {
          ++t;
          continue;
        }
        TaskEnd e;
        e.task = static_cast<std::size_t>(t->first);
        e.rank = r;
        e.failed = true;
        e.failure =
            fmt::format("rank {} stopped answering for {:g} s while running this task (its process or node was lost)",
                        r, options_.rank_timeout);
        ended(e);
        t = running_.erase(t);
      }
    }
  }

  // A worker slot of another rank asks for a task: the next, or -1.
  void hand_out(const std::string& b, int rank) {
    std::size_t at = 0;
    const auto slot = take<std::int32_t>(b, at);
    const std::int64_t i = take_next();
    std::string reply;
    put<std::int64_t>(reply, i);
    if (i >= 0) {
      reply += tasks_[i];
      running_.emplace_back(i, rank);
    }
    send(reply, rank, kTaskBase + slot);
  }

  // A result ('R') or the end ('E', end_message) of a task another rank ran.
  void gather(const std::string& b, int rank) {
    std::size_t at = 0;
    const char kind = b[at++];
    const auto i = take<std::uint64_t>(b, at);
    if (kind == 'R') {
      std::lock_guard<std::mutex> lock(mutex_);
      if (farm_.on_result) farm_.on_result(i, b.substr(at));
      return;
    }
    TaskEnd e;
    e.task = i;
    e.rank = rank;
    e.failed = take<std::int32_t>(b, at) != 0;
    e.wall = take<double>(b, at);
    e.peak_memory_mb = take<double>(b, at);
    e.failure = b.substr(at);
    running_.erase(std::remove(running_.begin(), running_.end(), std::make_pair(static_cast<std::int64_t>(i), rank)),
                   running_.end());
    ended(e);
  }

  const std::vector<std::string>& tasks_;
  const Farm& farm_;
  const FarmOptions& options_;
  const int ranks_;
  FarmSummary summary_;
  std::mutex mutex_;  // the list and the callbacks
  std::size_t next_ = 0;
  int byes_ = 0;
  std::vector<Clock::time_point> heard_;
  std::vector<bool> spoke_, done_, lost_;               // done: said bye, or lost
  std::vector<std::pair<std::int64_t, int> > running_;  // (task, rank) handed to other ranks
};

void serve(const Farm& farm, const FarmOptions& options) {
  const Session& s = session();
  std::mutex mpi;  // MPI_THREAD_SERIALIZED
  auto worker = [&](std::int32_t slot) {
    for (;;) {
      std::string request;
      put<std::int32_t>(request, slot);
      {
        std::lock_guard<std::mutex> lock(mpi);
        send(request, 0, kRequest);
      }
      std::string b;
      MPI_Status st;
      for (;;) {
        {
          std::lock_guard<std::mutex> lock(mpi);
          if (receive(0, kTaskBase + slot, b, st)) break;
        }
        std::this_thread::sleep_for(kPoll);
      }
      std::size_t at = 0;
      const auto i = take<std::int64_t>(b, at);
      if (i < 0) return;
      TaskEnd e = detail::run_task(farm, b.substr(at), options.isolate, [&](const std::string& r) {
        std::string msg(1, 'R');
        put<std::uint64_t>(msg, static_cast<std::uint64_t>(i));
        msg += r;
        std::lock_guard<std::mutex> lock(mpi);
        send(msg, 0, kResult);
      });
      e.task = static_cast<std::size_t>(i);
      std::lock_guard<std::mutex> lock(mpi);
      send(end_message(e), 0, kResult);
    }
  };
  std::vector<std::thread> pool;
  const int workers = detail::worker_count(options, s.ranks_on_node);
  std::atomic<int> finished{0};
  for (int w = 0; w < workers; ++w)
    pool.emplace_back([&, w] {
      worker(w);
      ++finished;
    });
  // This rank is alive: a beat every second while its workers run (a task can take minutes).
  for (auto last = Clock::now(); finished < workers; std::this_thread::sleep_for(std::chrono::milliseconds(50))) {
    if (Clock::now() - last < kBeatEvery) continue;
    last = Clock::now();
    std::lock_guard<std::mutex> lock(mpi);
    send(std::string(), 0, kBeat);
  }
  for (auto& t : pool) t.join();
  send(std::string(), 0, kBye);
  std::string end;
  MPI_Status st;
  while (!receive(0, kEnd, end, st)) std::this_thread::sleep_for(kPoll);
  std::size_t at = 0;
  if (take<std::int32_t>(end, at) != 0) session().lost_rank = true;
}

}  // namespace

Place place() { return session().place; }
bool mpi_built() { return true; }
void abort_job(int code) {
  if (session().active && session().place.ranks > 1) MPI_Abort(MPI_COMM_WORLD, code);
}

namespace detail {
FarmSummary run_farm_mpi(const std::vector<std::string>& tasks, const Farm& farm, const FarmOptions& options) {
  if (session().place.rank == 0) return Coordinator(tasks, farm, options).run();
  serve(farm, options);
  FarmSummary summary;
  summary.ranks = session().place.ranks;
  summary.workers = detail::worker_count(options, session().ranks_on_node);
  return summary;
}
}  // namespace detail

#endif

}  // namespace symoro::parallel
