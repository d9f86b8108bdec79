#include "core/solver/ordering.h"

#include <metis.h>
#include <stdlib.h>  // random_r

#include <Eigen/OrderingMethods>
#include <cstdint>
#include <mutex>
#include <numeric>
#include <string>
#include <utility>

// METIS (Debian's build) draws its random matchings from the C library's rand(), seeded by
// srand() at each call from its seed option. That generator is one per process, and other
// libraries of a server draw from it too (gRPC, c-ares and OpenMesh import rand), so a draw on
// another thread during an ordering changed the ordering: the same mesh loaded twice could get
// two factors of different sizes (a 3k phantom's factor, 2,120 bytes apart, in a test run under
// load). These two definitions take the place of the C library's for the whole program (the
// dynamic linker binds libmetis's and the others' calls to the executable's definitions first)
// and give each thread its own generator: the C library's own algorithm (random_r with its
// default 128-byte state), so that one thread's sequence from a seed, and with it every
// ordering, is what the C library's rand() gives a program that has only that thread.
namespace {
// One thread's generator: zeroed as initstate_r requires, with glibc's default state size (its
// TYPE_3 generator) and, until srand(), the seed rand() has unseeded (1).
struct ThreadRandom {
  random_data data{};
  char state[128] = {};
  ThreadRandom() { initstate_r(1, state, sizeof state, &data); }
};
random_data* ThisThreadsRandom() {
  thread_local ThreadRandom random;
  return &random.data;
}
}  // namespace

extern "C" void srand(unsigned int seed) noexcept { srandom_r(seed, ThisThreadsRandom()); }

extern "C" int rand() noexcept {
  std::int32_t value = 0;
  random_r(ThisThreadsRandom(), &value);
  return value;
}

namespace deform {
namespace {

using ColMajorMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

// Adjacency of A without its diagonal, in METIS's CSR form.
void BuildGraph(const ColMajorMatrix& a, std::vector<idx_t>* xadj, std::vector<idx_t>* adjncy) {
  const int n = static_cast<int>(a.cols());
  xadj->assign(n + 1, 0);
  adjncy->clear();
  adjncy->reserve(a.nonZeros());
  for (int j = 0; j < n; ++j) {
    for (ColMajorMatrix::InnerIterator it(a, j); it; ++it) {
      if (it.row() != j) adjncy->push_back(it.row());
    }
    (*xadj)[j + 1] = static_cast<idx_t>(adjncy->size());
  }
}

std::vector<int> AmdOrdering(const ColMajorMatrix& a) {
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> inverse;
  Eigen::AMDOrdering<int> amd;
  amd(a.selfadjointView<Eigen::Lower>(), inverse);  // Eigen returns new -> old as its inverse
  return std::vector<int>(inverse.indices().data(), inverse.indices().data() + a.cols());
}

// `identity` is returned for a diagonal matrix: any order is fill-free.
StatusOr<std::vector<int>> MetisOrdering(const ColMajorMatrix& a, std::vector<int> identity) {
  std::vector<idx_t> xadj, adjncy;
  BuildGraph(a, &xadj, &adjncy);
  if (adjncy.empty()) return identity;
  idx_t nvtxs = static_cast<idx_t>(a.cols());
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = 1;  // deterministic ordering from run to run
  std::vector<idx_t> perm(nvtxs), iperm(nvtxs);
  // One METIS call at a time all the same (its random generator is the thread's own, above, but
  // METIS is not documented as safe to call from several threads): an ordering runs once per
  // mesh loaded, so the calls waiting on each other cost little.
  static std::mutex metis_calls;
  int rc;
  {
    const std::lock_guard<std::mutex> one_at_a_time(metis_calls);
    rc = METIS_NodeND(&nvtxs, xadj.data(), adjncy.data(), nullptr, options, perm.data(),
                      iperm.data());
  }
  if (rc != METIS_OK) {
    return Status::Internal("METIS_NodeND failed with code " + std::to_string(rc));
  }
  // METIS: row i of P A P^T is row perm[i].
  return std::vector<int>(perm.begin(), perm.end());
}

}  // namespace

const char* OrderingName(Ordering ordering) {
  switch (ordering) {
    case Ordering::kNatural:
      return "natural";
    case Ordering::kAmd:
      return "amd";
    case Ordering::kMetis:
      return "metis";
    case Ordering::kAuto:
      return "auto";
  }
  return "unknown";
}

StatusOr<Ordering> OrderingFromName(std::string_view name) {
  for (Ordering ordering :
       {Ordering::kNatural, Ordering::kAmd, Ordering::kMetis, Ordering::kAuto}) {
    if (name == OrderingName(ordering)) return ordering;
  }
  return Status::InvalidArgument("unknown ordering '" + std::string(name) +
                                 "' (known: natural, amd, metis, auto)");
}

StatusOr<std::vector<int>> FillReducingOrdering(const ColMajorMatrix& a, Ordering ordering) {
  const int n = static_cast<int>(a.cols());
  std::vector<int> identity(n);
  std::iota(identity.begin(), identity.end(), 0);
  if (ordering == Ordering::kNatural || n <= 1) return identity;
  switch (ordering) {
    case Ordering::kAmd:
      return AmdOrdering(a);
    case Ordering::kMetis:
      return MetisOrdering(a, std::move(identity));
    default:
      return Status::InvalidArgument(std::string("no single permutation for ordering ") +
                                     OrderingName(ordering));
  }
}

}  // namespace deform
