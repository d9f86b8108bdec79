// The budget of log lines for refusals: a burst, then the refill rate, the rest counted and
// reported by the next line written.
#include "service/base/log_budget.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>

namespace deform::service {
namespace {

using std::chrono::milliseconds;

TEST(LogBudgetTest, ABurstThenTheRateAndTheNextLineCountsWhatWasHeldBack) {
  LogBudget budget(/*lines_per_second=*/2, /*burst=*/3);
  const LogBudget::Clock::time_point start = LogBudget::Clock::now();
  std::uint64_t held_back = 99;
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(budget.Take(start, &held_back)) << i;
    EXPECT_EQ(held_back, 0u);
  }
  for (int i = 0; i < 7; ++i) EXPECT_FALSE(budget.Take(start, &held_back)) << i;
  EXPECT_FALSE(budget.Take(start + milliseconds(400), &held_back));  // 0.8 of a line refilled
  EXPECT_TRUE(budget.Take(start + milliseconds(500), &held_back));   // one line after 0.5 s
  EXPECT_EQ(held_back, 8u);
  EXPECT_FALSE(budget.Take(start + milliseconds(500), &held_back));
  // A long quiet time refills the burst, never more.
  const LogBudget::Clock::time_point later = start + std::chrono::hours(1);
  EXPECT_TRUE(budget.Take(later, &held_back));
  EXPECT_EQ(held_back, 1u);
  EXPECT_TRUE(budget.Take(later, &held_back));
  EXPECT_TRUE(budget.Take(later, &held_back));
  EXPECT_FALSE(budget.Take(later, &held_back));
  // A clock read before the last refill (another thread's earlier reading) refills nothing.
  EXPECT_FALSE(budget.Take(start, &held_back));
}

TEST(LogBudgetTest, TheNoteNamesTheLinesHeldBack) {
  EXPECT_EQ(HeldBackNote(0), "");
  EXPECT_EQ(HeldBackNote(41), " (and 41 more like it, not logged)");
}

}  // namespace
}  // namespace deform::service
