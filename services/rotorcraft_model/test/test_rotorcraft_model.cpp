// The 6-DOF rotorcraft model alone: trim controls within the actuator
// limits, thrust growing with collective. The cases that fly the model are
// with its simulation (services/vehicle_sim/test).

#include <gtest/gtest.h>

#include "ofn/rotorcraft_model/rotorcraft_model.hpp"

namespace ofn::vehicle {
namespace {

TEST(RotorcraftModel, TrimControlsLieWithinActuatorLimits) {
  const RotorcraftModel model;
  const auto& p = model.params();
  for (const Vec3& v : {Vec3(0, 0, 0), Vec3(3.048, 0, 0), Vec3(6.0, 0, 0)}) {
    const TrimResult t = trim(model, v, 0.0);
    ASSERT_TRUE(t.converged) << v.transpose();
    const auto c = t.controls.as_array(), lo = p.min_controls.as_array(),
               hi = p.max_controls.as_array();
    for (int i = 0; i < 4; ++i) {
      EXPECT_GT(c[i], lo[i]) << "channel " << i << " at " << v.transpose();
      EXPECT_LT(c[i], hi[i]) << "channel " << i << " at " << v.transpose();
    }
    // Collective is positive to carry the weight.
    EXPECT_GT(t.controls.collective, 0.0);
  }
}

TEST(RotorcraftModel, MoreCollectiveGivesMoreThrust) {
  const RotorcraftModel model;
  const auto& p = model.params();
  double previous = -1.0;
  for (double c = 0.0; c <= p.max_controls.collective + 1e-12; c += 0.01) {
    const double vi = model.steady_induced_velocity(c, Vec3::Zero());
    const double thrust = model.thrust(c, vi, Vec3::Zero());
    EXPECT_GT(thrust, previous) << "collective " << c;
    previous = thrust;
  }
  // At a fixed inflow too.
  EXPECT_GT(model.thrust(0.2, 6.0, Vec3::Zero()), model.thrust(0.1, 6.0, Vec3::Zero()));
}

}  // namespace
}  // namespace ofn::vehicle
