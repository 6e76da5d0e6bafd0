// The ground station's heartbeat watch: a service heard and then not for
// the silence is reported once, and again when it is heard once more.

#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "ofn/tools/heartbeat_watch.hpp"

namespace ofn::report {
namespace {

using Names = std::vector<std::string>;

TEST(HeartbeatWatch, ASilentServiceIsReportedOnceAndItsReturnToo) {
  HeartbeatWatch watch(3.0);
  for (double t = 0; t <= 10; t += 1) {
    watch.heard("mapper", t);
    if (t <= 4) watch.heard("controller", t);
  }
  // The controller's last heartbeat was at 4 s.
  EXPECT_TRUE(watch.check(6.9).silent.empty());
  const HeartbeatChanges at7 = watch.check(7.0);
  EXPECT_EQ(at7.silent, Names{"controller"});
  EXPECT_TRUE(at7.back.empty());
  EXPECT_EQ(watch.silent(), Names{"controller"});
  // Reported once, not at every check.
  EXPECT_TRUE(watch.check(9.0).silent.empty());
  watch.heard("controller", 11.0);
  const HeartbeatChanges at11 = watch.check(11.0);
  EXPECT_EQ(at11.back, Names{"controller"});
  EXPECT_TRUE(at11.silent.empty());
  EXPECT_TRUE(watch.silent().empty());
  EXPECT_TRUE(watch.check(12.0).back.empty());
}

TEST(HeartbeatWatch, EveryFollowerFallsSilentWithTheClock) {
  // vehicle_sim dies: the simulation clock stops, and every service on it
  // stops its heartbeat too; they are named together, sorted.
  HeartbeatWatch watch(3.0);
  for (const char* s : {"vehicle_sim", "rh_optimizer", "controller"}) watch.heard(s, 1.0);
  EXPECT_EQ(watch.check(4.5).silent, (Names{"controller", "rh_optimizer", "vehicle_sim"}));
}

TEST(HeartbeatWatch, AServiceNeverHeardIsNotReported) {
  HeartbeatWatch watch(3.0);
  watch.heard("mapper", 0.0);
  const HeartbeatChanges changes = watch.check(100.0);
  EXPECT_EQ(changes.silent, Names{"mapper"});
  EXPECT_EQ(watch.silent(), Names{"mapper"});  // not the services never heard
}

TEST(HeartbeatWatch, AHeartbeatNamingAnotherServiceIsNoSignOfLife) {
  HeartbeatWatch watch(3.0);
  EXPECT_TRUE(watch.heard("rh_optimizer", "rh_optimizer", 0.0));
  // A stranger's on the RH optimiser's channel, after it died at 0 s.
  for (double t = 1; t <= 10; t += 1) EXPECT_FALSE(watch.heard("rh_optimizer", "fuzz", t));
  EXPECT_EQ(watch.check(10.0).silent, Names{"rh_optimizer"});
}

TEST(HeartbeatWatch, TheSilenceMustBePositive) {
  EXPECT_THROW(HeartbeatWatch(0.0), std::invalid_argument);
  EXPECT_THROW(HeartbeatWatch(-1.0), std::invalid_argument);
  EXPECT_THROW(HeartbeatWatch(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
}

}  // namespace
}  // namespace ofn::report
