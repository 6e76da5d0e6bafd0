// An outside program using the installed ofn package: it round-trips a
// NAV_STATE message through LCM's encoding and checks it with ofn_common's
// validator, plans a global path round a cuboid with the pure global-planner
// core, and samples a B-spline (the flat outputs REF_TRAJ carries). Exit code 0 when
// every result is as expected.

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "ofn/common/channels.hpp"
#include "ofn/common/validate.hpp"
#include "ofn/global_planner/global_planner.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/common/bspline.hpp"

namespace {

int failures = 0;

void expect(bool ok, const char* what) {
  std::printf("%s: %s\n", ok ? "ok" : "FAILED", what);
  if (!ok) ++failures;
}

ofn::nav_state_t make_state() {
  ofn::nav_state_t msg{};
  msg.utime = 1234567;
  msg.frame = "NED";
  const double position[3] = {-30.48, 0.0, -36.58};
  const double velocity[3] = {3.048, 0.0, 0.0};
  for (int i = 0; i < 3; ++i) {
    msg.position[i] = position[i];
    msg.velocity[i] = velocity[i];
  }
  msg.quaternion[0] = 1.0;  // w x y z: level, heading north
  return msg;
}

}  // namespace

int main() {
  // 1. Message types (ofn::ofn_lcmtypes) and the validator (ofn::ofn_common).
  const ofn::nav_state_t sent = make_state();
  std::vector<char> buffer(static_cast<size_t>(sent.getEncodedSize()));
  const int encoded = sent.encode(buffer.data(), 0, static_cast<int>(buffer.size()));
  ofn::nav_state_t received{};
  const int decoded = received.decode(buffer.data(), 0, static_cast<int>(buffer.size()));
  std::printf("%s: %d bytes encoded, %d decoded, position (%.2f, %.2f, %.2f)\n",
              ofn::channels::kNavState, encoded, decoded, received.position[0],
              received.position[1], received.position[2]);
  expect(encoded == static_cast<int>(buffer.size()) && decoded == encoded,
         "nav_state_t encodes and decodes whole");
  expect(received.utime == sent.utime && received.frame == "NED" &&
             received.position[0] == sent.position[0] && received.velocity[0] == sent.velocity[0],
         "decoded nav_state_t equals the sent one");
  expect(ofn::validate(received).empty(), "validate() accepts it");
  ofn::nav_state_t bad = received;
  bad.position[1] = std::nan("");
  const std::string reason = ofn::validate(bad);
  std::printf("validate() of a NaN position: \"%s\"\n", reason.c_str());
  expect(!reason.empty(), "validate() refuses a NaN position");
  // A truncated buffer must not decode (the installed headers are hardened).
  expect(received.decode(buffer.data(), 0, encoded - 1) < 0, "a truncated message is refused");

  // 2. Pure core: a global path round one cuboid standing across the leg.
  ofn::planning::GlobalPlanner planner;
  ofn::planning::PlanRequest request;
  request.start = ofn::Vec3(0, 0, -20);
  request.leg_from = request.start;
  request.start_velocity = ofn::Vec3(3, 0, 0);
  request.goal = ofn::Vec3(120, 0, -20);
  ofn::planning::ObstacleBox box;
  box.id = 7;
  box.min_corner = ofn::Vec3(50, -10, -40);  // NED: z = -40 is the top, 40 m up
  box.max_corner = ofn::Vec3(60, 10, 0);
  request.obstacles.push_back(box);
  const ofn::planning::PlanResult plan = planner.plan(request);
  const double straight = (request.goal - request.start).norm();
  std::printf("global path: %s, %zu waypoints, %.1f m (straight line %.1f m), %d nodes\n",
              ofn::planning::to_string(plan.status), plan.waypoints.size(), plan.cost, straight,
              plan.nodes);
  expect(plan.status == ofn::planning::PlanStatus::kOk && plan.waypoints.size() >= 3 &&
             plan.cost > straight,
         "the planner goes round the cuboid");

  // 3. Pure core: a straight cubic B-spline, 10 m in 5 s, is at 5 m halfway.
  const ofn::BsplineBasis basis(3, 1);
  std::vector<ofn::Vec3> control;
  for (int i = 0; i < basis.num_control_points(); ++i)
    control.push_back(ofn::Vec3(10.0 * i / (basis.num_control_points() - 1), 0, -20));
  const ofn::BsplineTrajectory spline(3, basis.knots(), control, 5.0);
  const ofn::Vec3 middle = spline.position(2.5);
  std::printf("B-spline at t = 2.5 s: (%.3f, %.3f, %.3f)\n", middle.x(), middle.y(), middle.z());
  expect(std::abs(middle.x() - 5.0) < 1e-9, "the B-spline is halfway at half time");

  std::printf("%d failed\n", failures);
  return failures == 0 ? 0 : 1;
}
