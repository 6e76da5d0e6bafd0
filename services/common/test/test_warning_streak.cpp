// A streak of like warnings comes out as its first line and one summary.

#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

#include "ofn/common/warning_streak.hpp"

namespace ofn {
namespace {

using Lines = std::vector<std::string>;

TEST(WarningStreak, ARepeatIsCountedNotLogged) {
  WarningStreak streak("worst violation");
  EXPECT_EQ(streak.warn(1.0, "kept_previous", "t=1.00 s kept_previous: first", 3.0),
            Lines{"t=1.00 s kept_previous: first"});
  EXPECT_TRUE(streak.warn(1.1, "kept_previous", "t=1.10 s kept_previous: again", 70.0).empty());
  EXPECT_TRUE(streak.warn(1.2, "kept_previous", "t=1.20 s kept_previous: again", 5.0).empty());
  EXPECT_EQ(streak.repeats(), 2);
  const Lines end = streak.clear(1.3);
  ASSERT_EQ(end.size(), 1u);
  EXPECT_EQ(end[0],
            "kept_previous: 2 more from t=1.00 to 1.20 s (worst violation 70), over at t=1.30 s");
  EXPECT_EQ(streak.repeats(), 0);
  // Over: the same kind again begins a new streak, logged in full.
  EXPECT_EQ(streak.warn(2.0, "kept_previous", "t=2.00 s kept_previous: later", 1.0).size(), 1u);
}

TEST(WarningStreak, AnotherKindEndsTheStreakAndIsLogged) {
  WarningStreak streak;
  streak.warn(1.0, "kept_previous", "first", 1.0);
  streak.warn(1.1, "kept_previous", "again", 2.0);
  const Lines lines = streak.warn(1.2, "braking", "t=1.20 s braking: no plan", 9.0);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], "kept_previous: 1 more from t=1.00 to 1.10 s (worst 2), over at t=1.20 s");
  EXPECT_EQ(lines[1], "t=1.20 s braking: no plan");
}

TEST(WarningStreak, ALoneWarningNeedsNoSummary) {
  WarningStreak streak;
  EXPECT_EQ(streak.warn(1.0, "braking", "one", 1.0).size(), 1u);
  EXPECT_TRUE(streak.clear(1.1).empty());
  EXPECT_TRUE(streak.clear(1.2).empty());  // nothing open
}

TEST(WarningStreak, ANonFiniteFigureDoesNotPoisonTheWorst) {
  WarningStreak streak;
  streak.warn(1.0, "kept_previous", "first", std::numeric_limits<double>::quiet_NaN());
  streak.warn(1.1, "kept_previous", "again", std::numeric_limits<double>::infinity());
  streak.warn(1.2, "kept_previous", "again", 4.0);
  EXPECT_EQ(streak.clear(1.3)[0],
            "kept_previous: 2 more from t=1.00 to 1.20 s (worst 4), over at t=1.30 s");
}

}  // namespace
}  // namespace ofn
