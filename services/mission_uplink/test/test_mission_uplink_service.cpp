// The mission uplink: a scenario's plan as the MISSION it sends, in SI.

#include <gtest/gtest.h>

#include <string>

#include "ofn/common/scenario.hpp"
#include "ofn/common/validate/mission.hpp"
#include "ofn/mission_t.hpp"
#include "ofn/mission_uplink/mission_uplink_service.hpp"

namespace ofn {
namespace {

const std::string kOpenScenario = std::string(OFN_SOURCE_DIR) + "/sim/scenarios/open.yaml";

TEST(MissionUplink, MissionFromScenarioCarriesThePlanInSI) {
  const Scenario s = load_scenario(kOpenScenario);
  const mission_t m = uplink::mission_from_scenario(s, 7);
  EXPECT_EQ(validate(m), "");
  EXPECT_EQ(m.mission_id, 7);
  EXPECT_EQ(m.name, "open");
  EXPECT_EQ(m.num_waypoints, 2);
  ASSERT_EQ(m.waypoints.size(), 2u);
  EXPECT_NEAR(m.waypoints[1].position[0], 152.4, 1e-9);
  EXPECT_NEAR(m.waypoints[1].position[2], -36.576, 1e-9);
  EXPECT_NEAR(m.waypoints[1].capture_radius, 3.048, 1e-9);
  EXPECT_NEAR(m.cruise_speed, 3.048, 1e-9);
  EXPECT_NEAR(m.limits.max_accel, 0.48768, 1e-9);
}

}  // namespace
}  // namespace ofn
