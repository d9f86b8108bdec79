// StiffnessSwitch: one refactorization at a time, the newest waiting update, the newest finished
// factorization, and versions.
#include "service/deform/stiffness_switch.h"

#include <gtest/gtest.h>

#include <memory>
#include <optional>

namespace deform::service {
namespace {

using Factorization = std::shared_ptr<const MaterialFactorization>;

Factorization NewFactorization() { return std::make_shared<MaterialFactorization>(); }

StiffnessSwitch::Update UpdateWithVersion(std::uint64_t version) {
  StiffnessSwitch::Update update;
  update.version = version;
  update.stiffness.region_weights.push_back({1, static_cast<double>(version)});
  return update;
}

TEST(StiffnessSwitchTest, StartsWithTheInitialFactorizationAsVersionZero) {
  const Factorization initial = NewFactorization();
  StiffnessSwitch stiffness;
  stiffness.Reset(initial);
  EXPECT_EQ(stiffness.current(), initial);
  EXPECT_EQ(stiffness.current_version(), 0u);
  EXPECT_FALSE(stiffness.busy());
  EXPECT_FALSE(stiffness.has_next());
  EXPECT_FALSE(stiffness.refactor_running());
}

TEST(StiffnessSwitchTest, TheNewestUpdateWaitsBehindTheRunningRefactorization) {
  StiffnessSwitch stiffness;
  stiffness.Reset(NewFactorization());
  stiffness.RefactorStarted();
  EXPECT_TRUE(stiffness.busy());
  EXPECT_FALSE(stiffness.Wait(UpdateWithVersion(2)).has_value());
  EXPECT_EQ(stiffness.Wait(UpdateWithVersion(3)), std::optional<std::uint64_t>(2));
  stiffness.RefactorEnded();
  EXPECT_TRUE(stiffness.busy());  // version 3 still waits
  const std::optional<StiffnessSwitch::Update> waiting = stiffness.TakeWaiting();
  ASSERT_TRUE(waiting.has_value());
  EXPECT_EQ(waiting->version, 3u);
  EXPECT_EQ(waiting->stiffness.region_weights.front().second, 3.0);
  EXPECT_FALSE(stiffness.TakeWaiting().has_value());
  EXPECT_FALSE(stiffness.busy());
}

TEST(StiffnessSwitchTest, TheNewestFinishedFactorizationIsAppliedAndReplacesCurrent) {
  const Factorization initial = NewFactorization();
  const Factorization first = NewFactorization();
  const Factorization second = NewFactorization();
  StiffnessSwitch stiffness;
  stiffness.Reset(initial);
  EXPECT_FALSE(stiffness.SetNext(first, 1).has_value());
  EXPECT_EQ(stiffness.current(), initial);  // not before ApplyNext
  EXPECT_EQ(stiffness.SetNext(second, 2), std::optional<std::uint64_t>(1));
  ASSERT_TRUE(stiffness.has_next());
  EXPECT_EQ(stiffness.ApplyNext(), 2u);
  EXPECT_EQ(stiffness.current(), second);
  EXPECT_EQ(stiffness.current_version(), 2u);
  EXPECT_FALSE(stiffness.has_next());
}

TEST(StiffnessSwitchTest, ResetForgetsEverything) {
  StiffnessSwitch stiffness;
  stiffness.Reset(NewFactorization());
  stiffness.RefactorStarted();
  (void)stiffness.Wait(UpdateWithVersion(2));
  (void)stiffness.SetNext(NewFactorization(), 1);
  stiffness.ApplyNext();
  const Factorization initial = NewFactorization();
  stiffness.Reset(initial);
  EXPECT_EQ(stiffness.current(), initial);
  EXPECT_EQ(stiffness.current_version(), 0u);
  EXPECT_FALSE(stiffness.busy());
}

}  // namespace
}  // namespace deform::service
