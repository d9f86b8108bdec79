#include "core/solver/sparse_cholesky.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <random>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "core/base/cancel_token.h"
#include "tests/core/solver/up_looking_reference.h"

namespace deform {
namespace {

using ColMajorMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

// A random sparse symmetric positive definite matrix: a graph Laplacian plus a positive diagonal.
ColMajorMatrix RandomSpdMatrix(int n, int edges_per_row, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  std::uniform_real_distribution<double> weight(0.1, 2.0);
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::VectorXd diagonal = Eigen::VectorXd::Constant(n, 0.5);
  for (int i = 0; i < n; ++i) {
    for (int e = 0; e < edges_per_row; ++e) {
      const int j = pick(rng);
      if (j == i) continue;
      const double w = weight(rng);
      triplets.emplace_back(i, j, -w);
      triplets.emplace_back(j, i, -w);
      diagonal[i] += w;
      diagonal[j] += w;
    }
  }
  for (int i = 0; i < n; ++i) triplets.emplace_back(i, i, diagonal[i]);
  ColMajorMatrix a(n, n);
  a.setFromTriplets(triplets.begin(), triplets.end());
  a.makeCompressed();
  return a;
}

Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> RandomRightHandSides(int n,
                                                                               unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> b(n, 3);
  for (int i = 0; i < b.size(); ++i) b.data()[i] = normal(rng);
  return b;
}

class SparseCholeskyTest : public ::testing::TestWithParam<Ordering> {};

TEST_P(SparseCholeskyTest, SolveMatchesDenseCholesky) {
  const int n = 300;
  const ColMajorMatrix a = RandomSpdMatrix(n, 3, 7);
  auto symbolic = SymbolicCholesky::Analyze(a, GetParam());
  ASSERT_TRUE(symbolic.ok()) << symbolic.status().ToString();
  auto factor = CholeskyFactor::Factorize(*symbolic, a);
  ASSERT_TRUE(factor.ok()) << factor.status().ToString();

  const auto b = RandomRightHandSides(n, 11);
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> x(n, 3);
  std::vector<double> work(factor->WorkSize());
  ASSERT_TRUE(factor->Solve3(b.data(), x.data(), work.data()).ok());

  const Eigen::MatrixXd dense = Eigen::MatrixXd(a);
  const Eigen::MatrixXd expected = dense.llt().solve(Eigen::MatrixXd(b));
  EXPECT_LT((Eigen::MatrixXd(x) - expected).norm(), 1e-10 * expected.norm());
}

TEST_P(SparseCholeskyTest, SolveInPlaceEqualsSolveOutOfPlace) {
  const int n = 120;
  const ColMajorMatrix a = RandomSpdMatrix(n, 2, 3);
  auto factor = CholeskyFactor::Factorize(*SymbolicCholesky::Analyze(a, GetParam()), a);
  ASSERT_TRUE(factor.ok());
  auto b = RandomRightHandSides(n, 5);
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> x(n, 3);
  std::vector<double> work(factor->WorkSize());
  ASSERT_TRUE(factor->Solve3(b.data(), x.data(), work.data()).ok());
  ASSERT_TRUE(factor->Solve3(b.data(), b.data(), work.data()).ok());
  EXPECT_EQ(Eigen::MatrixXd(x), Eigen::MatrixXd(b));
}

TEST_P(SparseCholeskyTest, RefactorizationReusesTheAnalysis) {
  const int n = 200;
  ColMajorMatrix a = RandomSpdMatrix(n, 3, 13);
  auto symbolic = SymbolicCholesky::Analyze(a, GetParam());
  ASSERT_TRUE(symbolic.ok());
  // Same pattern, other values.
  ColMajorMatrix scaled = a;
  for (int k = 0; k < scaled.nonZeros(); ++k) scaled.valuePtr()[k] *= 1.0 + 0.01 * (k % 7);
  scaled = ColMajorMatrix(0.5 * (scaled + ColMajorMatrix(scaled.transpose())));
  scaled.makeCompressed();
  ASSERT_EQ(scaled.nonZeros(), a.nonZeros());
  auto reused = CholeskyFactor::Factorize(*symbolic, scaled);
  auto fresh = CholeskyFactor::Factorize(*SymbolicCholesky::Analyze(scaled, GetParam()), scaled);
  ASSERT_TRUE(reused.ok() && fresh.ok());
  const auto b = RandomRightHandSides(n, 17);
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> x1(n, 3), x2(n, 3);
  std::vector<double> work(reused->WorkSize());
  ASSERT_TRUE(reused->Solve3(b.data(), x1.data(), work.data()).ok());
  ASSERT_TRUE(fresh->Solve3(b.data(), x2.data(), work.data()).ok());
  EXPECT_LT((x1 - x2).norm(), 1e-12 * x2.norm());
}

TEST_P(SparseCholeskyTest, SupernodalFactorMatchesTheUpLookingOne) {
  for (const auto& [n, edges, seed] :
       {std::tuple{40, 2, 3u}, {300, 3, 5u}, {1500, 4, 9u}, {2500, 2, 13u}}) {
    const ColMajorMatrix a = RandomSpdMatrix(n, edges, seed);
    auto symbolic = SymbolicCholesky::Analyze(a, GetParam());
    ASSERT_TRUE(symbolic.ok());
    auto factor = CholeskyFactor::Factorize(*symbolic, a);
    ASSERT_TRUE(factor.ok()) << factor.status().ToString();
    EXPECT_LT(testing::DifferenceFromUpLookingFactor(*factor, **symbolic, a), 1e-13) << n;
  }
}

TEST_P(SparseCholeskyTest, UnitSolvesTogetherEqualOneAtATimeAndGiveTheInverse) {
  const int n = 1200;
  const ColMajorMatrix a = RandomSpdMatrix(n, 3, 21);
  auto symbolic = SymbolicCholesky::Analyze(a, GetParam());
  ASSERT_TRUE(symbolic.ok());
  auto factor = CholeskyFactor::Factorize(*symbolic, a);
  ASSERT_TRUE(factor.ok()) << factor.status().ToString();
  std::int64_t columns = 0;
  int supernodes = 0;
  factor->LongestUnitSolvePath(&columns, &supernodes);
  // 19 right-hand sides: two full blocks and a partial one, with a repeated column.
  std::vector<int> at;
  for (int t = 0; t < 19; ++t) at.push_back((t * 331 + 17) % n);
  at.push_back(at[3]);
  const int count = static_cast<int>(at.size());
  std::vector<int> paths(count * supernodes), lengths(count);
  std::vector<double> values(count * columns, -1.0);
  std::vector<double> work(factor->UnitSolvesWorkSize(), 0.0);
  factor->ForwardUnitSolves(at.data(), count, paths.data(), supernodes, lengths.data(),
                            values.data(), columns, work.data());
  EXPECT_TRUE(std::all_of(work.begin(), work.end(), [](double v) { return v == 0; }));

  std::vector<int> path(supernodes);
  std::vector<double> one(columns), single_work(n, 0.0);
  std::vector<std::vector<double>> dense(count, std::vector<double>(n, 0.0));
  for (int t = 0; t < count; ++t) {
    const int length =
        factor->ForwardUnitSolve(at[t], path.data(), one.data(), columns, single_work.data());
    ASSERT_EQ(length, lengths[t]) << t;
    std::int64_t offset = 0;
    for (int p = 0; p < length; ++p) {
      ASSERT_EQ(path[p], paths[t * supernodes + p]) << t;
      const int width = factor->SupernodeWidth(path[p]);
      for (int q = 0; q < width; ++q) {
        // Bit for bit: the same sums in the same order.
        ASSERT_EQ(one[offset + q], values[t * columns + offset + q]) << t << " " << p;
      }
      offset += width;
    }
    // Scatter y onto the factor's columns, to check y_l . y_j = (A^-1)_{i_l i_j}.
    std::int64_t column = 0;
    offset = 0;
    for (int p = 0; p < length; ++p) {
      const int width = factor->SupernodeWidth(path[p]);
      column = 0;
      for (int s = 0; s < path[p]; ++s) column += factor->SupernodeWidth(s);
      for (int q = 0; q < width; ++q) dense[t][column + q] = one[offset + q];
      offset += width;
    }
  }
  const Eigen::MatrixXd inverse = Eigen::MatrixXd(a).inverse();
  for (int l = 0; l < count; ++l) {
    for (int j = 0; j < count; ++j) {
      double dot = 0;
      for (int c = 0; c < n; ++c) dot += dense[l][c] * dense[j][c];
      EXPECT_NEAR(dot, inverse(at[l], at[j]), 1e-12 * inverse.diagonal().maxCoeff());
    }
  }
}

TEST_P(SparseCholeskyTest, TheBackwardHalfOfForwardUnitSolvesIsTheSolve) {
  // M^-1 sum_j e_{i_j} w_j^T = P^T L^-T sum_j y_j w_j^T with y_j the unit forward passes.
  const int n = 900;
  const ColMajorMatrix a = RandomSpdMatrix(n, 3, 23);
  auto symbolic = SymbolicCholesky::Analyze(a, GetParam());
  ASSERT_TRUE(symbolic.ok());
  auto factor = CholeskyFactor::Factorize(*symbolic, a);
  ASSERT_TRUE(factor.ok()) << factor.status().ToString();
  std::int64_t columns = 0;
  int supernodes = 0;
  factor->LongestUnitSolvePath(&columns, &supernodes);
  const std::vector<int> at = {5, 140, 141, 600, 899, 77, 312, 450, 451, 2};
  const int count = static_cast<int>(at.size());
  std::vector<int> paths(count * supernodes), lengths(count);
  std::vector<double> values(count * columns);
  std::vector<double> unit_work(factor->UnitSolvesWorkSize(), 0.0);
  factor->ForwardUnitSolves(at.data(), count, paths.data(), supernodes, lengths.data(),
                            values.data(), columns, unit_work.data());
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  std::vector<double> b(3 * n, 0.0), z(3 * n, 0.0);
  for (int t = 0; t < count; ++t) {
    const double w[3] = {normal(rng), normal(rng), normal(rng)};
    const double* y = values.data() + t * columns;
    for (int p = 0; p < lengths[t]; ++p) {
      const int s = paths[t * supernodes + p];
      for (int q = 0; q < factor->SupernodeWidth(s); ++q) {
        for (int c = 0; c < 3; ++c) z[3 * (factor->SupernodeFirstColumn(s) + q) + c] += w[c] * y[q];
      }
      y += factor->SupernodeWidth(s);
    }
    for (int c = 0; c < 3; ++c) b[3 * at[t] + c] += w[c];
  }
  std::vector<double> work(factor->WorkSize()), solved(3 * n), halved(3 * n);
  ASSERT_TRUE(factor->Solve3(b.data(), solved.data(), work.data()).ok());
  ASSERT_TRUE(factor->SolveBackward3(z.data(), halved.data(), work.data()).ok());
  double largest = 0, difference = 0;
  for (int v = 0; v < 3 * n; ++v) {
    largest = std::max(largest, std::abs(solved[v]));
    difference = std::max(difference, std::abs(solved[v] - halved[v]));
  }
  EXPECT_GT(largest, 0);
  EXPECT_LT(difference, 1e-12 * largest);
  // Two combinations in one pass (SolveBackwardMany, six columns): each half as its own
  // SolveBackward3.
  std::vector<double> doubled(3 * n), twice(6 * n), many_work(factor->WorkSizeMany(6));
  for (int v = 0; v < 3 * n; ++v) doubled[v] = -2 * z[v] + 1e-3 * v;
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < 3; ++c) {
      twice[6 * r + c] = z[3 * r + c];
      twice[6 * r + 3 + c] = doubled[3 * r + c];
    }
  }
  std::vector<double> second(3 * n);
  ASSERT_TRUE(factor->SolveBackward3(doubled.data(), second.data(), work.data()).ok());
  ASSERT_TRUE(factor->SolveBackwardMany(twice.data(), twice.data(), 6, many_work.data()).ok());
  double many_difference = 0;
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < 3; ++c) {
      many_difference = std::max(many_difference, std::abs(twice[6 * r + c] - halved[3 * r + c]));
      many_difference =
          std::max(many_difference, std::abs(twice[6 * r + 3 + c] - second[3 * r + c]));
    }
  }
  EXPECT_LT(many_difference, 1e-12 * largest);
  EXPECT_EQ(factor->SolveBackwardMany(twice.data(), twice.data(), 0, many_work.data()).code(),
            StatusCode::kInvalidArgument);
}

TEST_P(SparseCholeskyTest, TwoThreadsFactorizeExactlyAsOne) {
  const ColMajorMatrix a = RandomSpdMatrix(2500, 3, 21);
  auto symbolic = SymbolicCholesky::Analyze(a, GetParam());
  ASSERT_TRUE(symbolic.ok());
  ThreadTeam team(2);
  auto serial = CholeskyFactor::Factorize(*symbolic, a);
  auto parallel = CholeskyFactor::Factorize(*symbolic, a, nullptr, &team);
  ASSERT_TRUE(serial.ok() && parallel.ok());
  const ColMajorMatrix difference = serial->FactorMatrix() - parallel->FactorMatrix();
  EXPECT_EQ(difference.norm(), 0.0);
  CancelToken cancelled;
  cancelled.Cancel();
  EXPECT_EQ(CholeskyFactor::Factorize(*symbolic, a, &cancelled, &team).status().ToString(),
            "FAILED_PRECONDITION: cancelled during the numeric factorization");
}

TEST_P(SparseCholeskyTest, ACancelledFactorizationStopsAndAnUncancelledOneCompletes) {
  const int n = 3 * CholeskyFactor::kCancelCheckRows;
  ColMajorMatrix a = RandomSpdMatrix(n, 3, 29);
  auto symbolic = SymbolicCholesky::Analyze(a, GetParam());
  ASSERT_TRUE(symbolic.ok());
  CancelToken cancelled;
  cancelled.Cancel();
  const auto stopped = CholeskyFactor::Factorize(*symbolic, a, &cancelled);
  EXPECT_EQ(stopped.status().ToString(),
            "FAILED_PRECONDITION: cancelled during the numeric factorization");
  // A parent's cancel (the server's shutdown) reaches it too.
  CancelToken child(&cancelled);
  EXPECT_FALSE(CholeskyFactor::Factorize(*symbolic, a, &child).ok());
  CancelToken never;
  const auto done = CholeskyFactor::Factorize(*symbolic, a, &never);
  const auto plain = CholeskyFactor::Factorize(*symbolic, a);
  ASSERT_TRUE(done.ok() && plain.ok());
  const auto b = RandomRightHandSides(n, 31);
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> x1(n, 3), x2(n, 3);
  std::vector<double> work(done->WorkSize());
  ASSERT_TRUE(done->Solve3(b.data(), x1.data(), work.data()).ok());
  ASSERT_TRUE(plain->Solve3(b.data(), x2.data(), work.data()).ok());
  EXPECT_EQ((x1 - x2).norm(), 0.0);
}

TEST(Ordering, NamesRoundTrip) {
  for (Ordering ordering :
       {Ordering::kNatural, Ordering::kAmd, Ordering::kMetis, Ordering::kAuto}) {
    EXPECT_EQ(*OrderingFromName(OrderingName(ordering)), ordering);
  }
  EXPECT_EQ(OrderingFromName("colamd").status().code(), StatusCode::kInvalidArgument);
}

TEST(CholeskyFactor, AnEmptyFactorRefusesToSolve) {
  const CholeskyFactor empty;
  EXPECT_EQ(empty.size(), 0);
  EXPECT_EQ(empty.WorkSize(), 0u);
  double b[3] = {1, 2, 3};
  double x[3] = {7, 7, 7};
  const Status status = empty.Solve3(b, x, nullptr);
  EXPECT_EQ(status.code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(x[0], 7);  // nothing written
}

TEST(CholeskyFactor, FactorizeRefusesANullAnalysis) {
  const ColMajorMatrix a = RandomSpdMatrix(10, 2, 1);
  EXPECT_EQ(CholeskyFactor::Factorize(nullptr, a).status().code(), StatusCode::kInvalidArgument);
}

INSTANTIATE_TEST_SUITE_P(AllOrderings, SparseCholeskyTest,
                         ::testing::Values(Ordering::kNatural, Ordering::kAmd, Ordering::kMetis,
                                           Ordering::kAuto),
                         [](const auto& info) { return std::string(OrderingName(info.param)); });

// Every compiled solve kernel this CPU can run gives the dense answer, on matrices whose
// supernodes have widths and heights with every remainder modulo four (the kernels' tails).
class SolveKernelTest : public ::testing::TestWithParam<SolveKernel> {};

TEST_P(SolveKernelTest, MatchesDenseCholeskyOnEveryShape) {
  if (!SolveKernelAvailable(GetParam())) {
    GTEST_SKIP() << SolveKernelName(GetParam()) << " is not available on this build or CPU";
  }
  for (const int n : {1, 2, 3, 5, 6, 7, 37, 300, 301, 302, 303}) {
    for (const Ordering ordering : {Ordering::kNatural, Ordering::kAmd, Ordering::kMetis}) {
      const ColMajorMatrix a = RandomSpdMatrix(n, 4, 100 + n);
      auto symbolic = SymbolicCholesky::Analyze(a, ordering);
      ASSERT_TRUE(symbolic.ok()) << symbolic.status().ToString();
      auto factor = CholeskyFactor::Factorize(*symbolic, a);
      ASSERT_TRUE(factor.ok()) << factor.status().ToString();

      const auto b = RandomRightHandSides(n, 5 + n);
      Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> x(n, 3);
      std::vector<double> work(factor->WorkSize(), std::nan(""));  // the kernel must not read it
      ASSERT_TRUE(factor->Solve3(b.data(), x.data(), work.data(), GetParam()).ok());

      const Eigen::MatrixXd dense = Eigen::MatrixXd(a);
      const Eigen::MatrixXd expected = dense.llt().solve(Eigen::MatrixXd(b));
      EXPECT_LT((Eigen::MatrixXd(x) - expected).norm(), 1e-10 * expected.norm())
          << "n " << n << ", " << OrderingName(ordering);
    }
  }
}

// The batched solve: every column count from 1 to kMaxSolveColumns (every padding of the last
// four-wide vector) gives, frame by frame, Solve3's answer for that frame's three columns to 1e-12
// of its norm, on every supernode shape; `x` may alias `b`.
TEST_P(SolveKernelTest, ManyColumnsMatchThreeAtATime) {
  if (!SolveKernelAvailable(GetParam())) {
    GTEST_SKIP() << SolveKernelName(GetParam()) << " is not available on this build or CPU";
  }
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  for (const int n : {1, 2, 5, 7, 37, 301, 303}) {
    for (const Ordering ordering : {Ordering::kNatural, Ordering::kMetis}) {
      const ColMajorMatrix a = RandomSpdMatrix(n, 4, 200 + n);
      auto symbolic = SymbolicCholesky::Analyze(a, ordering);
      ASSERT_TRUE(symbolic.ok()) << symbolic.status().ToString();
      auto factor = CholeskyFactor::Factorize(*symbolic, a);
      ASSERT_TRUE(factor.ok()) << factor.status().ToString();
      std::vector<double> work3(factor->WorkSize());
      for (int columns = 1; columns <= kMaxSolveColumns; ++columns) {
        const RowMajor b = RowMajor::Random(n, columns);
        RowMajor x(n, columns);
        std::vector<double> work(factor->WorkSizeMany(columns), std::nan(""));
        ASSERT_TRUE(factor->SolveMany(b.data(), x.data(), columns, work.data(), GetParam()).ok());
        RowMajor in_place = b;
        ASSERT_TRUE(
            factor->SolveMany(in_place.data(), in_place.data(), columns, work.data(), GetParam())
                .ok());
        EXPECT_EQ((in_place - x).norm(), 0) << "columns " << columns;
        for (int first = 0; first < columns; first += 3) {
          const int count = std::min(3, columns - first);
          Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> b3 =
              Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>::Zero(n, 3);
          b3.leftCols(count) = b.middleCols(first, count);
          Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> x3(n, 3);
          ASSERT_TRUE(factor->Solve3(b3.data(), x3.data(), work3.data(), GetParam()).ok());
          const double difference = (x.middleCols(first, count) - x3.leftCols(count)).norm();
          EXPECT_LE(difference, 1e-12 * x3.norm())
              << "n " << n << ", " << OrderingName(ordering) << ", columns " << columns;
        }
      }
      RowMajor b = RowMajor::Random(n, kMaxSolveColumns + 1);
      std::vector<double> work(factor->WorkSizeMany(kMaxSolveColumns));
      EXPECT_EQ(factor->SolveMany(b.data(), b.data(), 0, work.data()).code(),
                StatusCode::kInvalidArgument);
      EXPECT_EQ(factor->SolveMany(b.data(), b.data(), kMaxSolveColumns + 1, work.data()).code(),
                StatusCode::kInvalidArgument);
    }
  }
  std::vector<double> b(3), work(8);
  EXPECT_EQ(CholeskyFactor().SolveMany(b.data(), b.data(), 3, work.data()).code(),
            StatusCode::kFailedPrecondition);
}

// Frames in arrays of their own (SolveFrames): each equals Solve3 of its three columns to 1e-12 of
// its norm, in place too, for every frame count; counts out of range are refused.
TEST_P(SolveKernelTest, FramesInTheirOwnArraysMatchThreeAtATime) {
  if (!SolveKernelAvailable(GetParam())) {
    GTEST_SKIP() << SolveKernelName(GetParam()) << " is not available on this build or CPU";
  }
  using Rhs = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
  constexpr int kMostFrames = kMaxSolveColumns / 3;
  for (const int n : {1, 7, 301}) {
    const ColMajorMatrix a = RandomSpdMatrix(n, 4, 500 + n);
    auto symbolic = SymbolicCholesky::Analyze(a, Ordering::kMetis);
    ASSERT_TRUE(symbolic.ok()) << symbolic.status().ToString();
    auto factor = CholeskyFactor::Factorize(*symbolic, a);
    ASSERT_TRUE(factor.ok()) << factor.status().ToString();
    std::vector<Rhs> b, expected, x;
    std::vector<double> work3(factor->WorkSize());
    for (int f = 0; f < kMostFrames; ++f) {
      b.push_back(Rhs::Random(n, 3));
      expected.emplace_back(n, 3);
      ASSERT_TRUE(factor->Solve3(b[f].data(), expected[f].data(), work3.data(), GetParam()).ok());
    }
    for (int frames = 1; frames <= kMostFrames; ++frames) {
      x = b;
      std::vector<const double*> in;
      std::vector<double*> out;
      for (int f = 0; f < frames; ++f) {
        in.push_back(b[f].data());
        out.push_back(x[f].data());
      }
      std::vector<double> work(factor->WorkSizeMany(3 * frames), std::nan(""));
      ASSERT_TRUE(factor->SolveFrames(in.data(), out.data(), frames, work.data(), GetParam()).ok());
      for (int f = 0; f < frames; ++f) {
        EXPECT_LE((x[f] - expected[f]).norm(), 1e-12 * expected[f].norm())
            << "n " << n << ", frame " << f << " of " << frames;
      }
      std::vector<Rhs> in_place(b.begin(), b.begin() + frames);
      std::vector<double*> both;
      for (Rhs& frame : in_place) both.push_back(frame.data());
      ASSERT_TRUE(
          factor->SolveFrames(both.data(), both.data(), frames, work.data(), GetParam()).ok());
      for (int f = 0; f < frames; ++f) EXPECT_EQ((in_place[f] - x[f]).norm(), 0) << f;
    }
    std::vector<const double*> in(kMostFrames + 1, b[0].data());
    std::vector<double*> out(kMostFrames + 1, x[0].data());
    std::vector<double> work(factor->WorkSizeMany(kMaxSolveColumns));
    EXPECT_EQ(factor->SolveFrames(in.data(), out.data(), 0, work.data()).code(),
              StatusCode::kInvalidArgument);
    EXPECT_EQ(factor->SolveFrames(in.data(), out.data(), kMostFrames + 1, work.data()).code(),
              StatusCode::kInvalidArgument);
  }
  const double* in[1] = {nullptr};
  double* out[1] = {nullptr};
  EXPECT_EQ(CholeskyFactor().SolveFrames(in, out, 1, nullptr).code(),
            StatusCode::kFailedPrecondition);
}

// Runs every part on its own thread (a thread per part per call: tests only), so the parts of a
// parallel solve really run side by side (and under TSan, any shared write is reported).
class ThreadPerPartRunner final : public ParallelRunner {
 public:
  void Run(int count, void (*part)(void* context, int index), void* context) override {
    std::vector<std::thread> threads;
    for (int i = 1; i < count; ++i) threads.emplace_back([=] { part(context, i); });
    part(context, 0);
    for (std::thread& thread : threads) thread.join();
  }
};

// A square grid's Laplacian plus a small diagonal: a mesh-like matrix whose nested dissection has
// a deep tree of separators.
ColMajorMatrix GridMatrix(int side) {
  std::vector<Eigen::Triplet<double>> entries;
  const auto at = [side](int i, int j) { return i * side + j; };
  for (int i = 0; i < side; ++i) {
    for (int j = 0; j < side; ++j) {
      double degree = 0.01;
      for (const auto& [di, dj] :
           {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
        if (i + di < 0 || i + di >= side || j + dj < 0 || j + dj >= side) continue;
        entries.emplace_back(at(i, j), at(i + di, j + dj), -1.0);
        degree += 1;
      }
      entries.emplace_back(at(i, j), at(i, j), degree);
    }
  }
  ColMajorMatrix a(side * side, side * side);
  a.setFromTriplets(entries.begin(), entries.end());
  a.makeCompressed();
  return a;
}

// The parallel solve, its parts on their own threads or on one, equals Solve3 to 1e-12 of the
// solution's norm for every number of parts, in place too; the plan puts most of a mesh-like
// matrix's factor in the parts.
TEST_P(SolveKernelTest, ParallelSolveMatchesSolve3) {
  if (!SolveKernelAvailable(GetParam())) {
    GTEST_SKIP() << SolveKernelName(GetParam()) << " is not available on this build or CPU";
  }
  using Rhs = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
  ThreadPerPartRunner threads;
  SerialRunner serial;
  struct Case {
    std::string name;
    ColMajorMatrix a;
  };
  std::vector<Case> cases;
  for (const int n : {2, 37, 303, 2000})
    cases.push_back({"random " + std::to_string(n), RandomSpdMatrix(n, 4, 300 + n)});
  cases.push_back({"grid 70", GridMatrix(70)});
  for (const Case& c : cases) {
    auto symbolic = SymbolicCholesky::Analyze(c.a, Ordering::kMetis);
    ASSERT_TRUE(symbolic.ok()) << symbolic.status().ToString();
    auto factor = CholeskyFactor::Factorize(*symbolic, c.a);
    ASSERT_TRUE(factor.ok()) << factor.status().ToString();
    const int n = static_cast<int>(c.a.rows());
    const Rhs b = Rhs::Random(n, 3);
    Rhs expected(n, 3);
    std::vector<double> work3(factor->WorkSize());
    ASSERT_TRUE(factor->Solve3(b.data(), expected.data(), work3.data(), GetParam()).ok());
    for (const int parts : {2, 3, 4}) {
      const ParallelSolvePlan plan = factor->PlanParallel(parts);
      if (plan.parts == 0) continue;  // too small to split (the 2-unknown case)
      EXPECT_EQ(plan.parts, parts);
      // The parts' rows and the top's partition the unknowns' rows.
      std::vector<int> owners(n, 0);
      for (const int row : plan.part_rows) ++owners[row];
      for (const int row : plan.top_columns) ++owners[row];
      EXPECT_EQ(std::count(owners.begin(), owners.end(), 1), n) << c.name << ", " << parts;
      ASSERT_EQ(plan.part_row_offsets.size(), static_cast<std::size_t>(parts) + 1);
      EXPECT_EQ(plan.part_row_offsets.back(), static_cast<int>(plan.part_rows.size()));
      if (c.name == "grid 70" && parts == 2) {
        EXPECT_LT(plan.top_share, 0.3) << parts;
        EXPECT_LT(plan.predicted_time_ratio, 0.8) << parts;
      }
      std::vector<double> work(factor->WorkSizeParallel(plan), std::nan(""));
      for (ParallelRunner* runner :
           {static_cast<ParallelRunner*>(&threads), static_cast<ParallelRunner*>(&serial)}) {
        Rhs x(n, 3);
        ASSERT_TRUE(
            factor->Solve3Parallel(plan, b.data(), x.data(), work.data(), runner, GetParam()).ok());
        EXPECT_LE((x - expected).norm(), 1e-12 * expected.norm()) << c.name << ", " << parts;
        Rhs in_place = b;
        ASSERT_TRUE(factor
                        ->Solve3Parallel(plan, in_place.data(), in_place.data(), work.data(),
                                         runner, GetParam())
                        .ok());
        EXPECT_LE((in_place - expected).norm(), 1e-12 * expected.norm()) << c.name;
      }
    }
    EXPECT_EQ(factor->PlanParallel(1).parts, 0);
  }
  std::vector<double> b(3), work(8);
  EXPECT_EQ(CholeskyFactor()
                .Solve3Parallel(ParallelSolvePlan(), b.data(), b.data(), work.data(), &serial)
                .code(),
            StatusCode::kFailedPrecondition);
}

// The parallel batched solve: for every frame count and number of parts, on threads or on one,
// each frame equals its Solve3 to 1e-12 of its norm, in place too (x[f] == b[f]); the work is
// poisoned (a NaN read would show); a plan without parts or a frame count out of range is
// refused with nothing written.
TEST_P(SolveKernelTest, ParallelFramesMatchSolve3) {
  if (!SolveKernelAvailable(GetParam())) {
    GTEST_SKIP() << SolveKernelName(GetParam()) << " is not available on this build or CPU";
  }
  using Rhs = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
  constexpr int kMostFrames = kMaxSolveColumns / 3;
  ThreadPerPartRunner threads;
  SerialRunner serial;
  std::vector<std::pair<std::string, ColMajorMatrix>> cases;
  for (const int n : {37, 303, 2000})
    cases.emplace_back("random " + std::to_string(n), RandomSpdMatrix(n, 4, 600 + n));
  cases.emplace_back("grid 50", GridMatrix(50));
  for (const auto& [name, a] : cases) {
    auto symbolic = SymbolicCholesky::Analyze(a, Ordering::kMetis);
    ASSERT_TRUE(symbolic.ok()) << symbolic.status().ToString();
    auto factor = CholeskyFactor::Factorize(*symbolic, a);
    ASSERT_TRUE(factor.ok()) << factor.status().ToString();
    const int n = static_cast<int>(a.rows());
    std::vector<Rhs> b, expected;
    std::vector<double> work3(factor->WorkSize());
    for (int f = 0; f < kMostFrames; ++f) {
      b.push_back(Rhs::Random(n, 3));
      expected.emplace_back(n, 3);
      ASSERT_TRUE(factor->Solve3(b[f].data(), expected[f].data(), work3.data(), GetParam()).ok());
    }
    for (const int parts : {2, 3}) {
      const ParallelSolvePlan plan = factor->PlanParallel(parts);
      ASSERT_EQ(plan.parts, parts) << name;
      for (int frames = 1; frames <= kMostFrames; ++frames) {
        std::vector<double> work(factor->WorkSizeFramesParallel(plan, frames), std::nan(""));
        for (ParallelRunner* runner :
             {static_cast<ParallelRunner*>(&threads), static_cast<ParallelRunner*>(&serial)}) {
          std::vector<Rhs> x(b.begin(), b.begin() + frames);
          std::vector<const double*> in;
          std::vector<double*> out;
          for (int f = 0; f < frames; ++f) {
            in.push_back(b[f].data());
            out.push_back(x[f].data());
            x[f].setConstant(std::nan(""));
          }
          ASSERT_TRUE(factor
                          ->SolveFramesParallel(plan, in.data(), out.data(), frames, work.data(),
                                                runner, GetParam())
                          .ok());
          for (int f = 0; f < frames; ++f) {
            EXPECT_LE((x[f] - expected[f]).norm(), 1e-12 * expected[f].norm())
                << name << ", " << parts << " parts, frame " << f << " of " << frames;
          }
          std::vector<Rhs> in_place(b.begin(), b.begin() + frames);
          std::vector<double*> both;
          for (Rhs& frame : in_place) both.push_back(frame.data());
          ASSERT_TRUE(factor
                          ->SolveFramesParallel(plan, both.data(), both.data(), frames, work.data(),
                                                runner, GetParam())
                          .ok());
          for (int f = 0; f < frames; ++f) {
            EXPECT_LE((in_place[f] - expected[f]).norm(), 1e-12 * expected[f].norm())
                << name << ", in place, frame " << f << " of " << frames;
          }
        }
      }
    }
    const ParallelSolvePlan plan = factor->PlanParallel(2);
    std::vector<double> work(factor->WorkSizeFramesParallel(plan, kMostFrames));
    Rhs untouched = b[0];
    std::vector<double*> both(kMostFrames + 1, untouched.data());
    EXPECT_EQ(
        factor->SolveFramesParallel(plan, both.data(), both.data(), 0, work.data(), &serial).code(),
        StatusCode::kInvalidArgument);
    EXPECT_EQ(factor
                  ->SolveFramesParallel(plan, both.data(), both.data(), kMostFrames + 1,
                                        work.data(), &serial)
                  .code(),
              StatusCode::kInvalidArgument);
    EXPECT_EQ(factor
                  ->SolveFramesParallel(ParallelSolvePlan(), both.data(), both.data(), 1,
                                        work.data(), &serial)
                  .code(),
              StatusCode::kInvalidArgument);
    EXPECT_EQ((untouched - b[0]).norm(), 0) << name;
  }
  double* none[1] = {nullptr};
  EXPECT_EQ(CholeskyFactor()
                .SolveFramesParallel(ParallelSolvePlan(), none, none, 1, nullptr, &serial)
                .code(),
            StatusCode::kFailedPrecondition);
}

// A float32 factor (RoundedToFloat32): every pass (three columns, many columns, the parallel
// parts) reads the same rounded values, so they agree with each other to 1e-12 as the double ones
// do; against the double factor they differ by the rounding only (well within 1e-5 on these
// well-conditioned matrices, and not zero: the floats are what is read), and the values take half
// the bytes.
TEST_P(SolveKernelTest, Float32FactorSolvesWithItsRoundedValues) {
  if (!SolveKernelAvailable(GetParam())) {
    GTEST_SKIP() << SolveKernelName(GetParam()) << " is not available on this build or CPU";
  }
  using Rhs = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  ThreadPerPartRunner threads;
  std::vector<std::pair<std::string, ColMajorMatrix>> cases;
  for (const int n : {1, 2, 5, 7, 37, 301, 303, 2000})
    cases.emplace_back("random " + std::to_string(n), RandomSpdMatrix(n, 4, 400 + n));
  cases.emplace_back("grid 40", GridMatrix(40));
  for (const auto& [name, a] : cases) {
    auto symbolic = SymbolicCholesky::Analyze(a, Ordering::kMetis);
    ASSERT_TRUE(symbolic.ok()) << symbolic.status().ToString();
    auto exact = CholeskyFactor::Factorize(*symbolic, a);
    ASSERT_TRUE(exact.ok()) << exact.status().ToString();
    const CholeskyFactor rounded = exact->RoundedToFloat32();
    EXPECT_FALSE(exact->stores_float32());
    ASSERT_TRUE(rounded.stores_float32()) << name;
    EXPECT_LT(rounded.bytes(), exact->bytes()) << name;
    EXPECT_EQ(rounded.RoundedToFloat32().bytes(), rounded.bytes()) << name;
    const int n = static_cast<int>(a.rows());
    const Rhs b = Rhs::Random(n, 3);
    Rhs expected(n, 3), x(n, 3);
    std::vector<double> work3(exact->WorkSize(), std::nan(""));
    ASSERT_TRUE(exact->Solve3(b.data(), expected.data(), work3.data(), GetParam()).ok());
    ASSERT_TRUE(rounded.Solve3(b.data(), x.data(), work3.data(), GetParam()).ok());
    const double difference = (x - expected).norm() / expected.norm();
    EXPECT_LE(difference, 1e-5) << name;
    if (n >= 5) {
      EXPECT_GT(difference, 1e-12) << name << ": the float32 values were not read";
    }
    // Many columns: two frames, each equal to the float32 Solve3 of its columns.
    RowMajor b6(n, 6), x6(n, 6);
    b6 << b, b;
    std::vector<double> work6(rounded.WorkSizeMany(6));
    ASSERT_TRUE(rounded.SolveMany(b6.data(), x6.data(), 6, work6.data(), GetParam()).ok());
    EXPECT_LE((x6.leftCols(3) - x).norm(), 1e-12 * x.norm()) << name;
    EXPECT_LE((x6.rightCols(3) - x).norm(), 1e-12 * x.norm()) << name;
    // The parallel solve on threads.
    const ParallelSolvePlan plan = rounded.PlanParallel(2);
    if (plan.parts == 0) continue;
    std::vector<double> work(rounded.WorkSizeParallel(plan), std::nan(""));
    Rhs parallel(n, 3);
    ASSERT_TRUE(
        rounded.Solve3Parallel(plan, b.data(), parallel.data(), work.data(), &threads, GetParam())
            .ok());
    EXPECT_LE((parallel - x).norm(), 1e-12 * x.norm()) << name;
    // The parallel batched solve on threads: two frames.
    std::vector<double> frames_work(rounded.WorkSizeFramesParallel(plan, 2), std::nan(""));
    Rhs first(n, 3), second(n, 3);
    const double* in[2] = {b.data(), b.data()};
    double* out[2] = {first.data(), second.data()};
    ASSERT_TRUE(
        rounded.SolveFramesParallel(plan, in, out, 2, frames_work.data(), &threads, GetParam())
            .ok());
    EXPECT_LE((first - x).norm(), 1e-12 * x.norm()) << name;
    EXPECT_LE((second - x).norm(), 1e-12 * x.norm()) << name;
  }
  EXPECT_FALSE(CholeskyFactor().RoundedToFloat32().stores_float32());
  EXPECT_EQ(CholeskyFactor().RoundedToFloat32().size(), 0);
}

INSTANTIATE_TEST_SUITE_P(AllKernels, SolveKernelTest,
                         ::testing::Values(SolveKernel::kBaseline, SolveKernel::kAvx2Fma,
                                           SolveKernel::kAvx512),
                         [](const auto& info) {
                           std::string name = SolveKernelName(info.param);  // "avx2+fma"
                           for (char& c : name) {
                             if (c == '+') c = '_';
                           }
                           return name;
                         });

TEST(SolveKernel, TheBestIsAvailable) {
  EXPECT_TRUE(SolveKernelAvailable(BestSolveKernel())) << SolveKernelName(BestSolveKernel());
  EXPECT_TRUE(SolveKernelAvailable(SolveKernel::kBaseline));
}

// P A P^T for permutation[new] = old.
ColMajorMatrix Permuted(const ColMajorMatrix& a, const std::vector<int>& permutation) {
  const int n = static_cast<int>(a.cols());
  std::vector<int> inverse(n);
  for (int k = 0; k < n; ++k) inverse[permutation[k]] = k;
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < n; ++j) {
    for (ColMajorMatrix::InnerIterator it(a, j); it; ++it) {
      t.emplace_back(inverse[it.row()], inverse[j], it.value());
    }
  }
  ColMajorMatrix c(n, n);
  c.setFromTriplets(t.begin(), t.end());
  return c;
}

// Eigen's own analysis of P A P^T in the given order: its factor's non-zeros, its elimination
// tree and its columns' non-zeros (diagonals included).
struct EigenAnalysis
    : Eigen::SimplicialLLT<ColMajorMatrix, Eigen::Lower, Eigen::NaturalOrdering<int>> {
  EigenAnalysis(const ColMajorMatrix& a, const std::vector<int>& permutation) {
    compute(Permuted(a, permutation));
  }
  std::int64_t factor_nonzeros() const { return matrixL().nestedExpression().nonZeros(); }
  std::vector<int> elimination_tree() const {
    return std::vector<int>(m_parent.data(), m_parent.data() + m_parent.size());
  }
  std::vector<std::int64_t> column_nonzeros() const {  // diagonal included (an LLT's are)
    return std::vector<std::int64_t>(m_nonZerosPerCol.data(),
                                     m_nonZerosPerCol.data() + m_nonZerosPerCol.size());
  }
};

// The analysis renumbers the fill-reducing ordering's columns in a postorder of its elimination
// tree: every subtree's columns are consecutive and end at its root, the fill is the ordering's
// own, and the tree it keeps (relabelled from the ordering's, not recomputed) is the renumbered
// matrix's own, as are its column counts, as Eigen finds them.
TEST(SymbolicCholesky, TheEliminationTreeIsPostorderedWithTheOrderingsFill) {
  const std::pair<std::string, ColMajorMatrix> matrices[] = {
      {"grid", GridMatrix(30)}, {"random", RandomSpdMatrix(600, 3, 5)}};
  for (const auto& [name, a] : matrices) {
    for (const Ordering ordering : {Ordering::kAmd, Ordering::kMetis}) {
      auto symbolic = SymbolicCholesky::Analyze(a, ordering);
      ASSERT_TRUE(symbolic.ok());
      const std::vector<int>& parent = (*symbolic)->elimination_tree();
      const int n = static_cast<int>(parent.size());
      // first[j]: the first column of j's subtree (its columns [first[j], j] when postordered).
      std::vector<int> first(n), size(n, 1);
      for (int j = 0; j < n; ++j) first[j] = j;
      for (int j = 0; j < n; ++j) {
        ASSERT_TRUE(parent[j] == -1 || parent[j] > j) << name;
        if (parent[j] < 0) continue;
        first[parent[j]] = std::min(first[parent[j]], first[j]);
        size[parent[j]] += size[j];
      }
      for (int j = 0; j < n; ++j) {
        EXPECT_EQ(j - first[j] + 1, size[j])
            << name << ", " << OrderingName(ordering) << ", column " << j;
      }
      auto fill_reducing = FillReducingOrdering(a, ordering);
      ASSERT_TRUE(fill_reducing.ok());
      EXPECT_EQ((*symbolic)->factor_nonzeros(), EigenAnalysis(a, *fill_reducing).factor_nonzeros())
          << name << ", " << OrderingName(ordering);
      const EigenAnalysis renumbered(a, (*symbolic)->permutation());
      EXPECT_EQ(parent, renumbered.elimination_tree()) << name << ", " << OrderingName(ordering);
      std::vector<std::int64_t> column_nonzeros(n);
      for (int j = 0; j < n; ++j) column_nonzeros[j] = (*symbolic)->column_nonzeros(j);
      EXPECT_EQ(column_nonzeros, renumbered.column_nonzeros())
          << name << ", " << OrderingName(ordering);
    }
  }
}

// METIS draws its random matchings from rand(): orderings computed on several threads at once must
// each be the one computed alone (ordering.cc gives each thread its own rand() generator, and
// FillReducingOrdering lets one METIS call run at a time).
TEST(FillReducingOrdering, MetisOrdersAlikeOnSeveralThreadsAtOnce) {
  const std::pair<std::string, ColMajorMatrix> matrices[] = {
      {"grid", GridMatrix(60)}, {"random", RandomSpdMatrix(4000, 3, 17)}};
  for (const auto& [name, matrix] : matrices) {
    const ColMajorMatrix& a = matrix;  // a structured binding cannot be captured in C++17
    const auto alone = FillReducingOrdering(a, Ordering::kMetis);
    ASSERT_TRUE(alone.ok());
    constexpr int kThreads = 4;
    constexpr int kRounds = 6;
    std::vector<int> differing(kThreads, 0);
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t) {
      threads.emplace_back([&, t] {
        for (int round = 0; round < kRounds; ++round) {
          const auto ordering = FillReducingOrdering(a, Ordering::kMetis);
          if (!ordering.ok() || *ordering != *alone) ++differing[t];
        }
      });
    }
    for (std::thread& thread : threads) thread.join();
    for (int t = 0; t < kThreads; ++t) {
      EXPECT_EQ(differing[t], 0) << name << ": thread " << t
                                 << "'s orderings differ from one alone";
    }
  }
}

// METIS draws from rand(), which other libraries in a server call too (gRPC among them): another
// thread's draws must not change an ordering (each thread has its own generator, ordering.cc).
TEST(FillReducingOrdering, MetisOrdersAlikeWhileAnotherThreadDrawsFromRand) {
  const ColMajorMatrix a = GridMatrix(60);
  const auto alone = FillReducingOrdering(a, Ordering::kMetis);
  ASSERT_TRUE(alone.ok());
  std::atomic<bool> stop{false};
  std::atomic<unsigned> draws{0};
  std::thread drawer([&] {
    std::srand(12345);
    while (!stop.load(std::memory_order_relaxed)) {
      static_cast<void>(std::rand());
      draws.fetch_add(1, std::memory_order_relaxed);
    }
  });
  while (draws.load() == 0) std::this_thread::yield();
  int differing = 0;
  for (int round = 0; round < 8; ++round) {
    const auto ordering = FillReducingOrdering(a, Ordering::kMetis);
    if (!ordering.ok() || *ordering != *alone) ++differing;
  }
  stop = true;
  drawer.join();
  EXPECT_EQ(differing, 0) << "orderings changed by another thread's rand()";
}

TEST(SparseCholesky, MetisOrderingFillsLessThanNatural) {
  // A 2D grid Laplacian: nested dissection beats the natural (banded) order.
  const ColMajorMatrix a = GridMatrix(40);
  auto metis = SymbolicCholesky::Analyze(a, Ordering::kMetis);
  auto natural = SymbolicCholesky::Analyze(a, Ordering::kNatural);
  ASSERT_TRUE(metis.ok() && natural.ok());
  EXPECT_LT((*metis)->factor_nonzeros(), (*natural)->factor_nonzeros());
}

TEST(SparseCholesky, AutoOrderingKeepsTheSmallerFactor) {
  const ColMajorMatrix a = RandomSpdMatrix(400, 3, 21);
  auto amd = SymbolicCholesky::Analyze(a, Ordering::kAmd);
  auto metis = SymbolicCholesky::Analyze(a, Ordering::kMetis);
  auto chosen = SymbolicCholesky::Analyze(a, Ordering::kAuto);
  ASSERT_TRUE(amd.ok() && metis.ok() && chosen.ok());
  EXPECT_EQ((*chosen)->factor_nonzeros(),
            std::min((*amd)->factor_nonzeros(), (*metis)->factor_nonzeros()));
  EXPECT_NE((*chosen)->ordering(), Ordering::kAuto);
}

TEST(SparseCholesky, IndefiniteMatrixIsRefused) {
  ColMajorMatrix a = RandomSpdMatrix(50, 2, 1);
  a.coeffRef(10, 10) = -1.0;
  auto factor = CholeskyFactor::Factorize(*SymbolicCholesky::Analyze(a, Ordering::kAmd), a);
  ASSERT_FALSE(factor.ok());
  EXPECT_EQ(factor.status().code(), StatusCode::kInternal);
  EXPECT_NE(factor.status().message().find("not positive definite"), std::string::npos);
  // The pivot named is the negative diagonal's column in the factor's order (no column before it
  // depends on it), on one thread or two.
  auto symbolic = SymbolicCholesky::Analyze(a, Ordering::kAmd);
  const std::vector<int>& permutation = (*symbolic)->permutation();
  const int column =
      static_cast<int>(std::find(permutation.begin(), permutation.end(), 10) - permutation.begin());
  const std::string pivot = "(pivot " + std::to_string(column) + " is ";
  EXPECT_NE(factor.status().message().find(pivot), std::string::npos) << factor.status().ToString();
  ThreadTeam team(2);
  const auto parallel = CholeskyFactor::Factorize(*symbolic, a, nullptr, &team);
  EXPECT_NE(parallel.status().message().find(pivot), std::string::npos)
      << parallel.status().ToString();
}

TEST(SparseCholesky, MissingDiagonalIsRefused) {
  ColMajorMatrix a(3, 3);
  a.insert(0, 0) = 1;
  a.insert(1, 2) = 1;
  a.insert(2, 1) = 1;
  a.insert(2, 2) = 1;
  a.makeCompressed();
  auto symbolic = SymbolicCholesky::Analyze(a, Ordering::kNatural);
  ASSERT_FALSE(symbolic.ok());
  EXPECT_EQ(symbolic.status().code(), StatusCode::kInvalidArgument);
}

TEST(SparseCholesky, OtherPatternIsRefused) {
  const ColMajorMatrix a = RandomSpdMatrix(40, 2, 1);
  const ColMajorMatrix other = RandomSpdMatrix(40, 3, 2);
  auto factor = CholeskyFactor::Factorize(*SymbolicCholesky::Analyze(a, Ordering::kAmd), other);
  EXPECT_FALSE(factor.ok());
}

}  // namespace
}  // namespace deform
