#include "bench/cholmod_anchor.h"

#ifdef DEFORM_BENCH_HAVE_CHOLMOD
#include <cholmod.h>
#include <dlfcn.h>

#include <algorithm>
#include <chrono>
#endif

namespace deform::bench {

#ifdef DEFORM_BENCH_HAVE_CHOLMOD
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// OpenBLAS's thread count after asking for `threads`, when libblas.so.3 is OpenBLAS; 0 otherwise.
int SetBlasThreads(int threads) {
  using SetThreads = void (*)(int);
  using GetThreads = int (*)();
  const auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
  const auto get = reinterpret_cast<GetThreads>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  if (set == nullptr || get == nullptr) return 0;
  set(threads);
  return get();
}

class Cholmod final : public CholmodAnchor {
 public:
  Cholmod() {
    cholmod_start(&common_);
    common_.supernodal = CHOLMOD_SUPERNODAL;
    common_.nmethods = 1;
    common_.method[0].ordering = CHOLMOD_GIVEN;
    common_.postorder = false;  // the permutation is postordered already: keep it as it is
  }
  ~Cholmod() override {
    if (factor_ != nullptr) cholmod_free_factor(&factor_, &common_);
    if (matrix_ != nullptr) cholmod_free_sparse(&matrix_, &common_);
    cholmod_finish(&common_);
  }

  bool Analyze(const Eigen::SparseMatrix<double>& a, const std::vector<int>& permutation) {
    const int n = static_cast<int>(a.rows());
    matrix_ = cholmod_allocate_sparse(n, n, a.nonZeros(), /*sorted=*/true, /*packed=*/true,
                                      /*stype=*/1, CHOLMOD_REAL, &common_);
    if (matrix_ == nullptr) return false;
    std::copy(a.outerIndexPtr(), a.outerIndexPtr() + n + 1, static_cast<int*>(matrix_->p));
    std::copy(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros(), static_cast<int*>(matrix_->i));
    std::copy(a.valuePtr(), a.valuePtr() + a.nonZeros(), static_cast<double*>(matrix_->x));
    std::vector<int> perm(permutation);
    const auto start = std::chrono::steady_clock::now();
    factor_ = cholmod_analyze_p(matrix_, perm.data(), nullptr, 0, &common_);
    analyze_seconds_ = SecondsSince(start);
    return factor_ != nullptr;
  }

  double Factorize(int threads) override {
    blas_threads_ = SetBlasThreads(threads);
    const auto start = std::chrono::steady_clock::now();
    const bool ok =
        cholmod_factorize(matrix_, factor_, &common_) != 0 && common_.status == CHOLMOD_OK;
    const double seconds = SecondsSince(start);
    return ok ? seconds : -1;
  }
  int blas_threads() const override { return blas_threads_; }
  double analyze_seconds() const override { return analyze_seconds_; }
  bool supernodal() const override { return factor_ != nullptr && factor_->is_super != 0; }
  double factor_nonzeros() const override { return common_.lnz; }

 private:
  cholmod_common common_;
  cholmod_sparse* matrix_ = nullptr;
  cholmod_factor* factor_ = nullptr;
  double analyze_seconds_ = 0;
  int blas_threads_ = 0;
};

}  // namespace

bool CholmodAnchor::Available() { return true; }

std::unique_ptr<CholmodAnchor> CholmodAnchor::Create(const Eigen::SparseMatrix<double>& a,
                                                     const std::vector<int>& permutation) {
  auto anchor = std::make_unique<Cholmod>();
  if (!anchor->Analyze(a, permutation)) return nullptr;
  return anchor;
}

#else

bool CholmodAnchor::Available() { return false; }

std::unique_ptr<CholmodAnchor> CholmodAnchor::Create(const Eigen::SparseMatrix<double>&,
                                                     const std::vector<int>&) {
  return nullptr;
}

#endif

}  // namespace deform::bench
