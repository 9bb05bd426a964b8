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

FarmSummary coordinate(const std::vector<std::string>& tasks, const Farm& farm, const FarmOptions& options) {
  const Session& s = session();
  FarmSummary summary;
  summary.ranks = s.place.ranks;
  summary.workers = detail::worker_count(options, s.ranks_on_node);
  summary.tasks.resize(tasks.size());
  std::mutex m;  // the list and the callbacks
  std::size_t next = 0;
  // Every task is handed out here, to this rank's workers and to the others: Farm::stop is
  // asked before each, as the local farm does; once stopped, every rank is told there is none.
  auto take_next = [&]() -> std::int64_t {
    std::lock_guard<std::mutex> lock(m);
    if (!summary.stopped && next < tasks.size() && farm.stop && farm.stop()) summary.stopped = true;
    return !summary.stopped && next < tasks.size() ? static_cast<std::int64_t>(next++) : -1;
  };
  auto ended = [&](TaskEnd e) {
    std::lock_guard<std::mutex> lock(m);
    summary.tasks[e.task] = e;
    if (farm.on_end) farm.on_end(e);
  };
  auto worker = [&] {
    for (std::int64_t i; (i = take_next()) >= 0;) {
      TaskEnd e = detail::run_task(farm, tasks[i], options.isolate, [&](const std::string& r) {
        std::lock_guard<std::mutex> lock(m);
        if (farm.on_result) farm.on_result(static_cast<std::size_t>(i), r);
      });
      e.task = static_cast<std::size_t>(i);
      ended(e);
    }
  };
  std::vector<std::thread> pool;
  for (int w = 0; w < summary.workers; ++w) pool.emplace_back(worker);

  // Every other rank sends something at least every second (kBeat); one silent for longer than
  // rank_timeout is taken as lost (its process or node died; the job goes on only when the
  // launcher lets it, e.g. Open MPI's --mca orte_enable_recovery 1): its tasks in flight fail
  // with that reason and the others finish.
  int byes = 0;
  std::vector<Clock::time_point> heard(s.place.ranks, Clock::now());
  // Before its first message a rank gets ten times as long: it may still be reading the study's
  // inputs (a study's finished records, on a slow shared file system).
  std::vector<bool> spoke(s.place.ranks, false);
  std::vector<bool> done(s.place.ranks, false), lost(s.place.ranks, false);  // done: said bye, or lost
  std::vector<std::pair<std::int64_t, int>> running;  // (task, rank) handed to other ranks
  const auto timeout = std::chrono::duration<double>(options.rank_timeout);
  std::string b;
  MPI_Status st;
  while (byes < s.place.ranks - 1) {
    if (!receive(MPI_ANY_SOURCE, MPI_ANY_TAG, b, st)) {
      const auto now = Clock::now();
      for (int r = 1; r < s.place.ranks; ++r) {
        if (done[r] || now - heard[r] < (spoke[r] ? 1 : 10) * timeout) continue;
        done[r] = lost[r] = true;
        ++byes;
        session().lost_rank = true;
        for (auto t = running.begin(); t != running.end();) {
          if (t->second != r) {
            ++t;
            continue;
          }
          TaskEnd e;
          e.task = static_cast<std::size_t>(t->first);
          e.rank = r;
          e.failed = true;
          e.failure = fmt::format("rank {} stopped answering for {:g} s while running this task (its process or node was lost)",
                                  r, options.rank_timeout);
          ended(e);
          t = running.erase(t);
        }
      }
      std::this_thread::sleep_for(kPoll);
      continue;
    }
    heard[st.MPI_SOURCE] = Clock::now();
    spoke[st.MPI_SOURCE] = true;
    if (lost[st.MPI_SOURCE]) continue;  // a rank taken as lost that was only slow: too late
    std::size_t at = 0;
    if (st.MPI_TAG == kRequest) {
      const auto slot = take<std::int32_t>(b, at);
      const std::int64_t i = take_next();
      std::string reply;
      put<std::int64_t>(reply, i);
      if (i >= 0) {
        reply += tasks[i];
        running.emplace_back(i, st.MPI_SOURCE);
      }
      send(reply, st.MPI_SOURCE, kTaskBase + slot);
    } else if (st.MPI_TAG == kResult) {
      const char kind = b[at++];
      const auto i = take<std::uint64_t>(b, at);
      if (kind == 'R') {
        std::lock_guard<std::mutex> lock(m);
        if (farm.on_result) farm.on_result(i, b.substr(at));
      } else {
        TaskEnd e;
        e.task = i;
        e.rank = st.MPI_SOURCE;
        e.failed = take<std::int32_t>(b, at) != 0;
        e.wall = take<double>(b, at);
        e.peak_memory_mb = take<double>(b, at);
        e.failure = b.substr(at);
        running.erase(std::remove(running.begin(), running.end(), std::make_pair(static_cast<std::int64_t>(i), st.MPI_SOURCE)),
                      running.end());
        ended(e);
      }
    } else if (st.MPI_TAG == kBye) {
      done[st.MPI_SOURCE] = true;
      ++byes;
    }
  }
  for (auto& t : pool) t.join();
  for (std::size_t i = next; i < tasks.size(); ++i) summary.tasks[i] = TaskEnd{i, 0, true, "stopped"};
  // The end, to every rank still there, with whether one was lost: then no rank calls
  // MPI_Finalize, which would wait for the lost one forever.
  std::string end;
  put<std::int32_t>(end, session().lost_rank);
  for (int r = 1; r < s.place.ranks; ++r)
    if (!lost[r]) send(end, r, kEnd);
  return summary;
}

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
  if (session().place.rank == 0) return coordinate(tasks, farm, options);
  serve(farm, options);
  FarmSummary summary;
  summary.ranks = session().place.ranks;
  summary.workers = detail::worker_count(options, session().ranks_on_node);
  return summary;
}
}  // namespace detail

#endif

}  // namespace symoro::parallel
