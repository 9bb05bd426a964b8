// A farm of independent tasks (a study's trajectories, a dataset's runs) over worker threads,
// worker processes and MPI ranks.
//
// Rank 0 holds the task list and hands tasks out in order, one at a time, to whichever worker
// asks next (its own threads and the other ranks' threads alike): the list's order (longest
// first) and dynamic assignment keep a slow worker from holding the others. A task's results
// are texts; they reach rank 0 as they are emitted and rank 0 alone handles them (saves them,
// prints progress). Without an MPI launcher (or without the MPI build) the job is one rank and
// the farm is a pool of threads on this machine.
//
// Isolation (FarmOptions::isolate) runs each task in a forked process of its own: a task that
// crashes or is killed (out of memory) becomes a failed task with the signal named, and the
// rank lives on; and every task starts from the same process state, whichever rank and thread
// runs it and whatever ran before, so its results do not depend on the rank count or on the
// order of tasks (the solvers keep state between calls: docs/identification.md).
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace symoro::parallel {

// This process's place in its job: rank 0 of 1 unless it was started by an MPI launcher
// (mpirun, srun) and built with MPI (SYMORO_MPI). The first call initializes MPI then.
struct Place {
  int rank = 0;
  int ranks = 1;
  bool coordinator() const { return rank == 0; }
};
Place place();

// Whether this build has MPI.
bool mpi_built();

// Ends the job after an error on one rank: MPI_Abort when the job has more than one rank (the
// others would wait for it forever), else nothing (the caller returns its exit code).
void abort_job(int code);

// Worker threads by default: as many as the cores the process is bound to (mpirun binds a rank
// to one core when it starts two ranks or fewer: then one worker), else the machine's cores
// shared among its ranks.
struct FarmOptions {
  int workers = 0;       // worker threads per rank; 0: the cores this rank may use (below)
  bool isolate = false;  // each task in a forked process of its own (see above)
  // MPI: a rank silent this long (it sends a beat every second) is taken as lost and its tasks in
  // flight fail with that reason; the others finish. Takes effect only where the launcher keeps
  // the job alive after a process dies (Open MPI: --mca orte_enable_recovery 1); by default
  // mpirun ends the whole job, and a rerun resumes.
  double rank_timeout = 60;  // s
};

// What became of one task, on rank 0.
struct TaskEnd {
  std::size_t task = 0;
  int rank = 0;  // the rank that ran it
  bool failed = false;
  std::string failure;        // why: the exception's message, or the signal that killed it
  double wall = 0;            // s
  double peak_memory_mb = 0;  // the task's process's peak resident memory (isolated tasks only)
};

struct Farm {
  // Runs one task (on any rank; in a worker thread, or in its own process when isolated) and
  // emits its results, each a text, as they are ready. An exception fails the task; what it
  // emitted before stays emitted.
  std::function<void(const std::string& task, const std::function<void(const std::string&)>& emit)> work;
  // Rank 0 only, one call at a time: a result of task `task` (its index in the list).
  std::function<void(std::size_t task, const std::string& result)> on_result;
  // Rank 0 only, one call at a time, after the task's last result.
  std::function<void(const TaskEnd&)> on_end;
  // Rank 0 only, one call at a time with the others, before each task is handed out: true
  // stops the farm. No further task starts (those not started end failed, "stopped"); the tasks
  // in flight finish and their results arrive (on every rank, under MPI).
  std::function<bool()> stop;
};

struct FarmSummary {
  int ranks = 1;
  int workers = 1;             // worker threads per rank (on rank 0)
  std::vector<TaskEnd> tasks;  // rank 0: one per task, in list order
  bool stopped = false;        // Farm::stop said so: some tasks did not run
};

// Runs every task of rank 0's list; the other ranks' lists are not read (they receive their
// tasks from rank 0). Returns on every rank once all tasks have ended.
FarmSummary run_farm(const std::vector<std::string>& tasks, const Farm& farm, const FarmOptions& options);

}  // namespace symoro::parallel
