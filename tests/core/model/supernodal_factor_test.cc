// The supernodal numeric factorization on the models' own normal matrices (the phantom, the
// shared legs): the factor equals an up-looking one to round-off, and two threads give the same
// factor as one.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "core/io/model_input.h"
#include "core/io/phantom.h"
#include "core/model/deformation_model.h"
#include "core/solver/sparse_cholesky.h"
#include "tests/core/model/shared_leg_model.h"
#include "tests/core/solver/up_looking_reference.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

void ExpectFactorMatchesUpLooking(const DeformationModel& model) {
  Eigen::SparseMatrix<double> a = model.NormalMatrix(*model.default_factorization());
  a.makeCompressed();
  auto symbolic = SymbolicCholesky::Analyze(a, model.options().ordering);
  ASSERT_TRUE(symbolic.ok()) << symbolic.status().ToString();
  const auto serial = CholeskyFactor::Factorize(*symbolic, a);
  ASSERT_TRUE(serial.ok()) << serial.status().ToString();
  EXPECT_LT(testing::DifferenceFromUpLookingFactor(*serial, **symbolic, a), 1e-12);
  ThreadTeam team(2);
  const auto parallel = CholeskyFactor::Factorize(*symbolic, a, nullptr, &team);
  ASSERT_TRUE(parallel.ok()) << parallel.status().ToString();
  EXPECT_EQ(Eigen::SparseMatrix<double>(serial->FactorMatrix() - parallel->FactorMatrix()).norm(),
            0.0);
}

TEST(SupernodalFactor, MatchesTheUpLookingFactorOnThePhantom) {
  auto input = LoadModelInput("", "", 20'000);
  ASSERT_TRUE(input.ok()) << input.status().ToString();
  auto model = DeformationModel::Build(input->mesh, input->skeleton, ModelOptions::Paper());
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  ExpectFactorMatchesUpLooking(**model);
}

TEST(SupernodalFactor, MatchesTheUpLookingFactorOnTheSharedLegs) {
  DEFORM_SHARED_LEG_MODEL(small_leg);
  ExpectFactorMatchesUpLooking(*small_leg);
  DEFORM_REQUIRE_SHARED_FILE(leg_path, "leg/leg_25969.obj");
  DEFORM_REQUIRE_SHARED_FILE(skeleton_path, "leg/leg.tgf");
  auto leg = test_support::BuildModelFromFiles(leg_path, skeleton_path);
  ASSERT_TRUE(leg.ok()) << leg.status().ToString();
  ExpectFactorMatchesUpLooking(**leg);
}

}  // namespace
}  // namespace deform
