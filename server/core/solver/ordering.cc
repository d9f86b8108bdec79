#include "core/solver/ordering.h"

#include <metis.h>

#include <Eigen/OrderingMethods>
#include <mutex>
#include <numeric>
#include <string>
#include <utility>

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
  // METIS keeps its random generator's state (GKlib's Mersenne twister) in globals that every
  // thread shares: two calls at once race on it, which is undefined behaviour, and each may get an
  // ordering other than its own from the seed. Two threads building the 3k phantom's model at once
  // got nine different factor sizes in twenty builds, one thread always the same. So one call at a
  // time: an ordering takes milliseconds to a few seconds, once per mesh loaded.
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
