// The names logs, progress lines and the live view give the messages'
// enumerations: one per value, none left to "UNKNOWN".

#include <set>
#include <string>

#include <gtest/gtest.h>

#include "ofn/common/message_names.hpp"
#include "ofn/control_status_t.hpp"
#include "ofn/global_path_t.hpp"
#include "ofn/ref_traj_t.hpp"
#include "ofn/solver_stats_t.hpp"

namespace ofn {
namespace {

template <class Name>
void expect_distinct_names(Name name, std::initializer_list<int> values) {
  std::set<std::string> seen;
  for (int v : values) {
    const std::string n = name(v);
    EXPECT_NE(n, "UNKNOWN") << v;
    EXPECT_TRUE(seen.insert(n).second) << n << " twice";
  }
  EXPECT_STREQ(name(-100), "UNKNOWN");
}

TEST(MessageNames, EveryValueHasItsOwnName) {
  expect_distinct_names(
      control_mode_name,
      {control_status_t::HOLD, control_status_t::WAYPOINT, control_status_t::TRAJECTORY,
       control_status_t::NAV_STALE, control_status_t::DONE, control_status_t::SAFE_STOP});
  EXPECT_STREQ(control_mode_name(control_status_t::SAFE_STOP), "SAFE_STOP");
  expect_distinct_names(
      ref_traj_mode_name,
      {ref_traj_t::NOMINAL, ref_traj_t::AVOIDANCE, ref_traj_t::PREVIOUS, ref_traj_t::BRAKING,
       ref_traj_t::LOOK_AROUND, ref_traj_t::LOOK_AROUND_LEFT});
  expect_distinct_names(solver_status_name,
                        {solver_stats_t::SOLVED, solver_stats_t::KEPT_PREVIOUS,
                         solver_stats_t::BRAKING, solver_stats_t::NOT_RUN, solver_stats_t::DEFERRED,
                         solver_stats_t::LOOKING_AROUND, solver_stats_t::NO_ROUTE});
  expect_distinct_names(path_status_name, {global_path_t::OK, global_path_t::START_INSIDE_OBSTACLE,
                                           global_path_t::GOAL_INSIDE_OBSTACLE,
                                           global_path_t::NO_PATH, global_path_t::BACKTRACK});
}

TEST(MessageNames, TextFromTheBusIsOnePrintableLine) {
  EXPECT_EQ(printable("open"), "open");
  EXPECT_EQ(printable(std::string("N\x8d\nD\0", 5)), "N\\x8d\\x0aD\\x00");
  EXPECT_EQ(printable("a\\b"), "a\\x5cb");  // a backslash cannot fake an escape
  EXPECT_EQ(printable(std::string(100, 'x'), 8), "xxxxxxxx...");
}

}  // namespace
}  // namespace ofn
