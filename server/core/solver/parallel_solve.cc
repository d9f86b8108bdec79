#include "core/solver/parallel_solve.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <utility>

#include "core/base/compile_time_count.h"

namespace deform {
namespace {

// Part `part`'s supernodes (ascending) and their count.
const int* PartSupernodes(const ParallelSolvePlan& plan, int part) {
  return plan.part_supernodes.data() + plan.part_offsets[part];
}
int PartCount(const ParallelSolvePlan& plan, int part) {
  return plan.part_offsets[part + 1] - plan.part_offsets[part];
}

// Part p's solution rows and planar buffer in the aligned work.
struct PartBuffers {
  double* y;
  double* planar;
};

struct SolveContext {
  const SupernodalFactorView* factor;
  const ParallelSolvePlan* plan;
  SupernodeListPass forward;
  SupernodeListPass backward;
  const double* b;
  double* x;
  double* work;  // aligned to 32 bytes
  std::int64_t part_doubles;

  PartBuffers Buffers(int part) const {
    double* base = work + part * part_doubles;
    return {base, base + kSolveRowStride * static_cast<std::int64_t>(factor->size)};
  }
  double* Solution() const { return work; }
};

// Calls body(row) for every row of part `part`'s supernodes, in the order of their unknowns.
template <typename Body>
void ForEachRowOf(const ParallelSolvePlan& plan, int part, Body&& body) {
  for (int i = plan.part_row_offsets[part]; i < plan.part_row_offsets[part + 1]; ++i) {
    body(plan.part_rows[i]);
  }
}

// The rows [first, last) sorted by the unknown each holds.
void SortByUnknown(const SupernodalFactorView& f, std::vector<int>::iterator first,
                   std::vector<int>::iterator last) {
  std::sort(first, last, [&](int a, int b) { return f.permutation[a] < f.permutation[b]; });
}

void Gather(const SupernodalFactorView& f, const double* b, int row, double* y) {
  const double* source = b + 3 * static_cast<std::ptrdiff_t>(f.permutation[row]);
  double* t = y + kSolveRowStride * static_cast<std::ptrdiff_t>(row);
  t[0] = source[0];
  t[1] = source[1];
  t[2] = source[2];
  t[3] = 0;
}

void Scatter(const SupernodalFactorView& f, const double* y, int row, double* x) {
  double* target = x + 3 * static_cast<std::ptrdiff_t>(f.permutation[row]);
  const double* t = y + kSolveRowStride * static_cast<std::ptrdiff_t>(row);
  target[0] = t[0];
  target[1] = t[1];
  target[2] = t[2];
}

// A part's forward pass: its rows gathered into its buffer (part 0: the solution), the top rows of
// another part's buffer zeroed, its supernodes eliminated (another part's rows stay in its buffer
// for its backward pass).
void ForwardPart(void* context, int part) {
  const SolveContext& c = *static_cast<const SolveContext*>(context);
  const SupernodalFactorView& f = *c.factor;
  const PartBuffers own = c.Buffers(part);
  ForEachRowOf(*c.plan, part, [&](int row) { Gather(f, c.b, row, own.y); });
  if (part > 0) {
    for (const int col : c.plan->top_columns) {
      double* t = own.y + kSolveRowStride * static_cast<std::ptrdiff_t>(col);
      t[0] = t[1] = t[2] = t[3] = 0;
    }
  }
  c.forward(f, PartSupernodes(*c.plan, part), PartCount(*c.plan, part), own.y, own.planar);
}

// A part's backward pass on its own rows (part 0: the solution's; another part's first takes the
// top's solved rows from the solution), its rows then written to x. A part's supernodes read only
// their own rows and the top's.
void BackwardPart(void* context, int part) {
  const SolveContext& c = *static_cast<const SolveContext*>(context);
  const SupernodalFactorView& f = *c.factor;
  const PartBuffers own = c.Buffers(part);
  if (part > 0) {
    const double* solution = c.Solution();
    for (const int col : c.plan->top_columns) {
      const std::ptrdiff_t at = kSolveRowStride * static_cast<std::ptrdiff_t>(col);
      std::copy(solution + at, solution + at + kSolveRowStride, own.y + at);
    }
  }
  c.backward(f, PartSupernodes(*c.plan, part), PartCount(*c.plan, part), own.y, own.planar);
  ForEachRowOf(*c.plan, part, [&](int row) { Scatter(f, own.y, row, c.x); });
}

// ParallelSolveFrames' state: part p's batch rows at Rows(p) (part 0's are the solution's).
struct FramesContext {
  const SupernodalFactorView* factor;
  const ParallelSolvePlan* plan;
  const SolveKernelFunctions* passes;
  const double* const* b;
  double* const* x;
  int frames;
  int stride;    // doubles per batch row
  double* work;  // aligned to a batch vector

  double* Rows(int part) const {
    return work + static_cast<std::ptrdiff_t>(part) * stride * factor->size;
  }
  template <typename Value>  // double or const double
  Value* Row(Value* rows, int row) const {
    return rows + static_cast<std::ptrdiff_t>(stride) * row;
  }
};

// The frames' right-hand sides of unknown permutation[row] into `rows`' row, its padding zeroed;
// kFrames = c.frames, fixed at compile time so the row's copy unrolls.
template <int kFrames>
void GatherRow(const FramesContext& c, int row, double* rows) {
  const std::ptrdiff_t from = 3 * static_cast<std::ptrdiff_t>(c.factor->permutation[row]);
  double* t = c.Row(rows, row);
  for (int f = 0; f < kFrames; ++f) {
    const double* source = c.b[f] + from;
    t[3 * f] = source[0];
    t[3 * f + 1] = source[1];
    t[3 * f + 2] = source[2];
  }
  std::fill(t + 3 * kFrames, t + c.stride, 0.0);
}

// `rows`' row into the frames' solutions of unknown permutation[row].
template <int kFrames>
void ScatterRow(const FramesContext& c, int row, const double* rows) {
  const std::ptrdiff_t to = 3 * static_cast<std::ptrdiff_t>(c.factor->permutation[row]);
  const double* t = c.Row(rows, row);
  for (int f = 0; f < kFrames; ++f) {
    double* target = c.x[f] + to;
    target[0] = t[3 * f];
    target[1] = t[3 * f + 1];
    target[2] = t[3 * f + 2];
  }
}

// Gathers (kGather) or scatters `count` rows `listed` (in the order of their unknowns) of `rows`,
// each asking for the row kBatchRowsAhead on (PrefetchBatchRow).
template <bool kGather>
void CopyRows(const FramesContext& c, const int* listed, int count, double* rows) {
  WithCount<kMaxSolveColumns / 3>(c.frames, [&](auto frames) {
    constexpr int kFrames = decltype(frames)::value;
    for (int i = 0; i < count; ++i) {
      if (i + kBatchRowsAhead < count) {
        PrefetchBatchRow(c.Row(rows, listed[i + kBatchRowsAhead]), c.stride);
      }
      if constexpr (kGather) {
        GatherRow<kFrames>(c, listed[i], rows);
      } else {
        ScatterRow<kFrames>(c, listed[i], rows);
      }
    }
  });
}

// Part `part`'s rows (part_rows) gathered into or scattered from `rows`.
template <bool kGather>
void CopyPartRows(const FramesContext& c, int part, double* rows) {
  const int first = c.plan->part_row_offsets[part];
  CopyRows<kGather>(c, c.plan->part_rows.data() + first, c.plan->part_row_offsets[part + 1] - first,
                    rows);
}

// ForwardPart's batched counterpart.
void ForwardFramesPart(void* context, int part) {
  const FramesContext& c = *static_cast<const FramesContext*>(context);
  double* own = c.Rows(part);
  CopyPartRows<true>(c, part, own);
  if (part > 0) {
    for (const int col : c.plan->top_columns) std::fill_n(c.Row(own, col), c.stride, 0.0);
  }
  c.passes->forward_list_many(*c.factor, PartSupernodes(*c.plan, part), PartCount(*c.plan, part),
                              own, 3 * c.frames);
}

// BackwardPart's batched counterpart.
void BackwardFramesPart(void* context, int part) {
  const FramesContext& c = *static_cast<const FramesContext*>(context);
  double* own = c.Rows(part);
  if (part > 0) {
    const double* solution = c.Rows(0);
    for (const int col : c.plan->top_columns) {
      std::copy_n(c.Row(solution, col), c.stride, c.Row(own, col));
    }
  }
  c.passes->backward_list_many(*c.factor, PartSupernodes(*c.plan, part), PartCount(*c.plan, part),
                               own, 3 * c.frames);
  CopyPartRows<false>(c, part, own);
}

}  // namespace

ThreadTeam::ThreadTeam(int threads) {
  for (int i = 1; i < threads; ++i) helpers_.emplace_back([this] { Help(); });
}

ThreadTeam::~ThreadTeam() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (std::thread& helper : helpers_) helper.join();
}

void ThreadTeam::RunParts(std::unique_lock<std::mutex>& lock) {
  parts_.RunParts(lock, [this] { done_.notify_all(); });
}

void ThreadTeam::Run(int count, void (*part)(void* context, int index), void* context) {
  std::unique_lock<std::mutex> lock(mutex_);
  parts_.Open(count, part, context);
  ++job_;
  wake_.notify_all();
  RunParts(lock);
  done_.wait(lock, [this] { return parts_.all_finished(); });
  parts_.Close();
}

void ThreadTeam::Help() {
  std::unique_lock<std::mutex> lock(mutex_);
  std::uint64_t seen = 0;
  while (true) {
    wake_.wait(lock, [&] { return stopping_ || job_ != seen; });
    if (stopping_) return;
    seen = job_;
    RunParts(lock);
  }
}

ParallelSolvePlan PlanParallelSolve(const SupernodalFactorView& f, int parts) {
  ParallelSolvePlan plan;
  const int count = f.num_supernodes;
  if (parts < 2 || count < 2) return plan;
  // The supernodal elimination tree: a supernode's parent holds its first row below its block.
  std::vector<int> supernode_of(static_cast<std::size_t>(f.size));
  int widest = 0;
  for (int s = 0; s < count; ++s) {
    widest = std::max(widest, f.supernode_columns[s + 1] - f.supernode_columns[s]);
    for (int col = f.supernode_columns[s]; col < f.supernode_columns[s + 1]; ++col) {
      supernode_of[col] = s;
    }
  }
  std::vector<int> parent(count, -1);
  std::vector<double> subtree(count, 0);
  std::vector<std::vector<int>> children(count);
  std::vector<int> roots;
  for (int s = 0; s < count; ++s) {
    const int width = f.supernode_columns[s + 1] - f.supernode_columns[s];
    const std::int64_t rows = f.row_pointers[s + 1] - f.row_pointers[s];
    subtree[s] += static_cast<double>(rows) * width;  // children come first: theirs added already
    if (rows > width) {
      parent[s] = supernode_of[f.row_indices[f.row_pointers[s] + width]];
      subtree[parent[s]] += subtree[s];
      children[parent[s]].push_back(s);
    } else {
      roots.push_back(s);
    }
  }
  double total = 0;
  for (const int r : roots) total += subtree[r];
  // Split the largest subtree until the subtrees fill `parts` bins evenly (greedy, largest first).
  std::vector<int> candidates = roots;
  std::vector<int> top;
  std::vector<std::vector<int>> bins;
  std::vector<double> load;
  const auto by_cost = [&](int a, int b) { return subtree[a] > subtree[b]; };
  for (int iteration = 0; iteration < 4 * count; ++iteration) {
    std::sort(candidates.begin(), candidates.end(), by_cost);
    bins.assign(parts, {});
    load.assign(parts, 0);
    for (const int c : candidates) {
      const int lightest =
          static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
      bins[lightest].push_back(c);
      load[lightest] += subtree[c];
    }
    const double largest = *std::max_element(load.begin(), load.end());
    const double sum = std::accumulate(load.begin(), load.end(), 0.0);
    if (largest <= 1.05 * sum / parts || children[candidates.front()].empty()) break;
    const int split = candidates.front();
    candidates.erase(candidates.begin());
    top.push_back(split);
    candidates.insert(candidates.end(), children[split].begin(), children[split].end());
  }
  if (*std::min_element(load.begin(), load.end()) <= 0) return plan;  // nothing to run alongside
  // The heaviest part first: a runner's calling thread takes the parts in order and its helpers
  // start a wake-up later, so theirs should be the lighter. Measured faster than the parts in
  // packing order where the subtrees below the top differ (bench/RESULTS.md, "Parallel solve and
  // split batches").
  std::vector<int> order(parts);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return load[a] > load[b]; });
  std::vector<std::vector<int>> heaviest_first;
  for (const int b : order) heaviest_first.push_back(std::move(bins[b]));
  bins = std::move(heaviest_first);
  // Each bin's subtrees, whole, ascending.
  plan.parts = parts;
  plan.part_offsets.push_back(0);
  std::vector<int> stack;
  for (const std::vector<int>& bin : bins) {
    const std::size_t first = plan.part_supernodes.size();
    for (const int root : bin) {
      stack.assign(1, root);
      while (!stack.empty()) {
        const int s = stack.back();
        stack.pop_back();
        plan.part_supernodes.push_back(s);
        stack.insert(stack.end(), children[s].begin(), children[s].end());
      }
    }
    std::sort(plan.part_supernodes.begin() + static_cast<std::ptrdiff_t>(first),
              plan.part_supernodes.end());
    plan.part_offsets.push_back(static_cast<int>(plan.part_supernodes.size()));
  }
  plan.part_row_offsets.push_back(0);
  for (int p = 0; p < parts; ++p) {
    const std::size_t first = plan.part_rows.size();
    for (int i = plan.part_offsets[p]; i < plan.part_offsets[p + 1]; ++i) {
      const int s = plan.part_supernodes[i];
      for (int col = f.supernode_columns[s]; col < f.supernode_columns[s + 1]; ++col) {
        plan.part_rows.push_back(col);
      }
    }
    SortByUnknown(f, plan.part_rows.begin() + static_cast<std::ptrdiff_t>(first),
                  plan.part_rows.end());
    plan.part_row_offsets.push_back(static_cast<int>(plan.part_rows.size()));
  }
  std::sort(top.begin(), top.end());
  plan.top = top;
  double top_cost = 0;
  for (const int s : top) {
    const int width = f.supernode_columns[s + 1] - f.supernode_columns[s];
    top_cost += static_cast<double>(f.row_pointers[s + 1] - f.row_pointers[s]) * width;
    for (int col = f.supernode_columns[s]; col < f.supernode_columns[s + 1]; ++col) {
      plan.top_columns.push_back(col);
    }
  }
  SortByUnknown(f, plan.top_columns.begin(), plan.top_columns.end());
  plan.widest_supernode = widest;
  plan.top_share = total > 0 ? top_cost / total : 0;
  plan.predicted_time_ratio =
      total > 0 ? (top_cost + *std::max_element(load.begin(), load.end())) / total : 1;
  return plan;
}

std::int64_t ParallelSolveWorkSize(int size, const ParallelSolvePlan& plan) {
  return plan.parts * SolveBuffersSize(size, plan.widest_supernode) + kSolveRowStride;
}

void ParallelSolve3(const SupernodalFactorView& f, const ParallelSolvePlan& plan,
                    SolveKernel kernel, const double* b, double* x, double* work,
                    ParallelRunner* runner) {
  const std::uintptr_t misalignment = reinterpret_cast<std::uintptr_t>(work) % 32;
  const SolveKernelFunctions& passes = SolveKernelFunctionsFor(kernel);
  SolveContext c{&f,
                 &plan,
                 passes.forward_list,
                 passes.backward_list,
                 b,
                 x,
                 work + (misalignment ? (32 - misalignment) / sizeof(double) : 0),
                 SolveBuffersSize(f.size, plan.widest_supernode)};
  double* solution = c.Solution();
  double* planar = c.Buffers(0).planar;
  for (const int col : plan.top_columns) Gather(f, b, col, solution);
  runner->Run(plan.parts, &ForwardPart, &c);
  for (int part = 1; part < plan.parts; ++part) {
    const double* other = c.Buffers(part).y;
    for (const int col : plan.top_columns) {
      const std::ptrdiff_t at = kSolveRowStride * static_cast<std::ptrdiff_t>(col);
      for (int k = 0; k < 3; ++k) solution[at + k] += other[at + k];
    }
  }
  const int top = static_cast<int>(plan.top.size());
  c.forward(f, plan.top.data(), top, solution, planar);
  c.backward(f, plan.top.data(), top, solution, planar);
  for (const int col : plan.top_columns) Scatter(f, solution, col, x);
  runner->Run(plan.parts, &BackwardPart, &c);
}

std::int64_t ParallelSolveFramesWorkSize(int size, const ParallelSolvePlan& plan, int frames) {
  return plan.parts * (SolveManyWorkSize(size, 3 * frames) - kSolveBatchLanes) + kSolveBatchLanes;
}

void ParallelSolveFrames(const SupernodalFactorView& f, const ParallelSolvePlan& plan,
                         SolveKernel kernel, const double* const* b, double* const* x, int frames,
                         double* work, ParallelRunner* runner) {
  const SolveKernelFunctions& passes = SolveKernelFunctionsFor(kernel);
  constexpr std::uintptr_t kAlignment = kSolveBatchLanes * sizeof(double);
  const std::uintptr_t misalignment = reinterpret_cast<std::uintptr_t>(work) % kAlignment;
  FramesContext c{&f,
                  &plan,
                  &passes,
                  b,
                  x,
                  frames,
                  BatchRowStride(passes.batch_lanes, 3 * frames),
                  work + (misalignment ? (kAlignment - misalignment) / sizeof(double) : 0)};
  double* solution = c.Rows(0);
  const int top_rows = static_cast<int>(plan.top_columns.size());
  CopyRows<true>(c, plan.top_columns.data(), top_rows, solution);
  runner->Run(plan.parts, &ForwardFramesPart, &c);
  for (int part = 1; part < plan.parts; ++part) {
    const double* other = c.Rows(part);
    for (const int col : plan.top_columns) {
      double* target = c.Row(solution, col);
      const double* source = c.Row(other, col);
      for (int k = 0; k < 3 * frames; ++k) target[k] += source[k];
    }
  }
  const int top = static_cast<int>(plan.top.size());
  passes.forward_list_many(f, plan.top.data(), top, solution, 3 * frames);
  passes.backward_list_many(f, plan.top.data(), top, solution, 3 * frames);
  CopyRows<false>(c, plan.top_columns.data(), top_rows, solution);
  runner->Run(plan.parts, &BackwardFramesPart, &c);
}

}  // namespace deform
