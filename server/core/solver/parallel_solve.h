// The triangular solves on several threads: the three-column solve of one right-hand side, and the
// batched solve of several frames.
//
// The supernodal elimination tree's disjoint subtrees are independent: in the forward pass
// (L y = b) a supernode updates only its ancestors' rows, in the backward pass (L^T x = y) it reads
// only theirs. A plan (PlanParallelSolve) splits the tree into `parts` groups of whole subtrees of
// about equal cost (the factor's values they hold) and the top: every supernode above them, the
// top separators of the nested-dissection ordering. The solve runs the parts' forward passes
// concurrently (part 0 on the solution, each other part on rows of its own whose top rows start
// at zero, added into the solution's top rows afterwards, so no two threads write one row), then
// the top's forward and backward passes on the calling thread, then the parts' backward passes
// concurrently, each where its forward pass left its rows (another part's rows first take the
// top's solved rows: a part's supernodes read only their own rows and the top's; no part's rows
// are copied to the solution), each writing only its own rows of x. The sums run in another order
// than Solve3's, so the result equals Solve3's to round-off (1e-12 of the solution's norm, tested).
//
// Who runs the parts is the caller's ParallelRunner: the service's runs them on the workers of
// its pool that are free (or free up) while parts are left and the rest on the calling thread;
// SerialRunner runs them all on the calling thread.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

#include "core/solver/supernodal_solve.h"

namespace deform {

// Runs the parts of one computation, possibly on other threads.
class ParallelRunner {
 public:
  // Calls part(context, i) exactly once for every i in [0, count), on the calling thread or
  // others, and returns once every call has returned. Allocation-free in the implementations here.
  virtual void Run(int count, void (*part)(void* context, int index), void* context) = 0;
  // How many other threads could take parts at this moment (a hint: it may change as soon as it
  // is read); callers split work only when it pays, e.g. when another thread is free.
  virtual int IdleHelpers() { return 0; }

 protected:
  ~ParallelRunner() = default;
};

// The parts of one computation as runners hand them out: taken in order by whichever thread asks
// next, counted as they finish. The one home of that loop for every runner with helper threads
// (ThreadTeam here, the service's runner on its worker pool). Not thread-safe by itself: every
// member is used under the runner's lock.
struct PartsInProgress {
  void (*part)(void*, int) = nullptr;  // null: no computation open
  void* context = nullptr;
  int count = 0;
  int next = 0;
  int finished = 0;

  void Open(int parts, void (*run)(void*, int), void* run_context) {
    part = run;
    context = run_context;
    count = parts;
    next = 0;
    finished = 0;
  }
  // After the last part has finished: a helper starting late finds nothing to run.
  void Close() {
    part = nullptr;
    context = nullptr;
    count = 0;
  }
  bool all_finished() const { return finished == count; }

  // Takes and runs parts until none is left. `lock` (a BasicLockable) is held on entry and on
  // return, and released while each part runs; `part_finished()` is called with it held after
  // each part.
  template <typename Lock, typename PartFinished>
  void RunParts(Lock& lock, PartFinished part_finished) {
    while (part != nullptr && next < count) {
      const int index = next++;
      void (*const run)(void*, int) = part;
      void* const argument = context;
      lock.unlock();
      run(argument, index);
      lock.lock();
      ++finished;
      part_finished();
    }
  }
};

// Every part on the calling thread, in order.
class SerialRunner final : public ParallelRunner {
 public:
  void Run(int count, void (*part)(void* context, int index), void* context) override {
    for (int i = 0; i < count; ++i) part(context, i);
  }
};

// A team of threads of its own (for benchmarks and tools; the service runs parts on its worker
// pool instead): the caller and `threads - 1` helpers take the parts in turn. Run is called from
// one thread at a time.
class ThreadTeam final : public ParallelRunner {
 public:
  explicit ThreadTeam(int threads);
  ~ThreadTeam();
  ThreadTeam(const ThreadTeam&) = delete;
  ThreadTeam& operator=(const ThreadTeam&) = delete;
  void Run(int count, void (*part)(void* context, int index), void* context) override;
  int IdleHelpers() override { return static_cast<int>(helpers_.size()); }

 private:
  void Help();
  // Takes and runs parts of the current job until none is left; called with `lock` held.
  void RunParts(std::unique_lock<std::mutex>& lock);

  std::mutex mutex_;
  std::condition_variable wake_;  // a new job, or stopping
  std::condition_variable done_;  // a part finished
  PartsInProgress parts_;
  std::uint64_t job_ = 0;
  bool stopping_ = false;
  std::vector<std::thread> helpers_;
};

// A split of one factor's supernodes (of its symbolic analysis: the same for every factor of it).
struct ParallelSolvePlan {
  int parts = 0;
  // Part p's supernodes, ascending: part_supernodes[part_offsets[p] .. part_offsets[p + 1]).
  // The heaviest part (by the factor's values) is part 0, which a runner's calling thread takes
  // first: its helpers start a wake-up later.
  std::vector<int> part_offsets;
  std::vector<int> part_supernodes;
  std::vector<int> top;  // the other supernodes, ascending
  // The top's rows (permuted order), in the order of the unknowns they hold (permutation[row]
  // ascending), as part_rows holds the parts'.
  std::vector<int> top_columns;
  // Part p's rows: part_rows[part_row_offsets[p] .. part_row_offsets[p + 1]), in the order of the
  // unknowns they hold, so a part gathers its right-hand sides and scatters its solution in the
  // order they lie in memory (one pass each way over b and x; the rows, one or two cache lines
  // each, are the scattered side).
  std::vector<int> part_row_offsets;
  std::vector<int> part_rows;
  int widest_supernode = 0;
  // The factor's values in the top (solved on one thread), and the time predicted against Solve3
  // ((top + largest part) / whole), both by the values read.
  double top_share = 0;
  double predicted_time_ratio = 1;
};

// The plan for `parts` (>= 2) parts, or a plan of 0 parts when the tree has no two subtrees to run
// side by side.
ParallelSolvePlan PlanParallelSolve(const SupernodalFactorView& factor, int parts);

// Doubles of work ParallelSolve3 needs: per part a four-double row per unknown and room for the
// widest supernode, and slack to align the rows.
std::int64_t ParallelSolveWorkSize(int size, const ParallelSolvePlan& plan);

// Solves P^T L L^T P x = b for three interleaved right-hand sides as Solve3 does, the parts of
// `plan` (made for this factor's analysis, parts >= 2) through `runner`. `x` may equal `b`.
// Allocation-free.
void ParallelSolve3(const SupernodalFactorView& factor, const ParallelSolvePlan& plan,
                    SolveKernel kernel, const double* b, double* x, double* work,
                    ParallelRunner* runner);

// Doubles of work ParallelSolveFrames needs for `frames` frames: per part a batch row per unknown
// (as wide as any kernel's: SolveManyWorkSize's), and slack to align the rows.
std::int64_t ParallelSolveFramesWorkSize(int size, const ParallelSolvePlan& plan, int frames);

// The batched solve of `frames` frames (1 to kMaxSolveColumns / 3; b[f] and x[f] as
// SolveFramesFunction's) split as ParallelSolve3 splits Solve3: the parts' subtrees on `runner`'s
// threads, each on batch rows of its own (part 0 on the solution's), the top on the calling thread.
// Each frame equals its Solve3 to round-off (the sums run in another order). Allocation-free.
void ParallelSolveFrames(const SupernodalFactorView& factor, const ParallelSolvePlan& plan,
                         SolveKernel kernel, const double* const* b, double* const* x, int frames,
                         double* work, ParallelRunner* runner);

}  // namespace deform
