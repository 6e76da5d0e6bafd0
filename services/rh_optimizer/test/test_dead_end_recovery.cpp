// The dead-end recovery's decisions (stuck -> look around -> escape or no
// route) and the escape legs the planner flies from a hover.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "ofn/rh_optimizer/dead_end_recovery.hpp"
#include "ofn/rh_optimizer/rh_planner.hpp"
#include "rh_step_inputs.hpp"

namespace ofn::rh {
namespace {

using testing_support::field_with;
using testing_support::kBenchmarkLimits;
using testing_support::kLegAltitude;
using testing_support::untimed;

// An escape leg: from a hover, to a point `to` (world NED), stopping there,
// with the forward-speed rule relaxed, as the service poses it.
StepInput escape_leg(const Vec3& from, const Vec3& to, ClearanceQuery clearance) {
  StepInput in;
  in.time = 100.0;
  RhProblem& p = in.problem;
  p.frame = GuidanceFrame::from_leg(from, to);
  p.position = from;
  p.target = to;
  p.terminal_x = p.frame.to_guidance(to).x();
  p.stop_at_target = true;
  p.limits = kBenchmarkLimits;
  p.limits.min_forward_speed = -kBenchmarkLimits.max_speed;
  p.clearance = std::move(clearance);
  in.global_path = {from, to};
  in.global_path_changed = true;
  return in;
}

TEST(EscapeLeg, ShortLegsFromAHoverAreSolved) {
  for (const double length : {8.0, 15.0, 30.0, 60.0}) {
    RhPlanner planner(untimed());
    const Vec3 from(50, 0, -kLegAltitude);
    const Vec3 to(50, -length, -kLegAltitude);
    const StepOutput out = planner.step(escape_leg(from, to, field_with({})));
    EXPECT_EQ(out.mode, StepMode::kSolved) << length << " m: " << out.reason;
    if (out.mode == StepMode::kSolved) {
      const BsplineTrajectory& t = out.trajectory;
      EXPECT_LT((t.position(t.duration()) - to).norm(), 0.5) << length;
      EXPECT_LT(t.velocity(t.duration()).norm(), 0.1) << length;
    }
  }
}

// A stop that ended a few centimetres inside R_s plus the planning margin
// (here 6.4 m from a wall, 6.6 m planned): from that hover a plan away from
// the wall must be feasible. It was not while the requirement grew at the
// speed limit from t = 0, faster than a vehicle at rest can move.
TEST(EscapeLeg, FromAHoverJustInsideThePlannedClearance) {
  using testing_support::Box;
  RhSettings settings = untimed();
  settings.clearance_margin = 0.5;
  RhPlanner planner(settings);
  // A wall at north 40..43, the vehicle 6.4 m short of it, leaving south.
  // The field measures from cell centres: the face cell's centre is 40.5.
  const Vec3 from(40.5 - 6.4, 0, -kLegAltitude);
  const Vec3 to(from.x() - 20.0, 0, -kLegAltitude);
  const StepInput in = escape_leg(from, to, field_with({Box{40, 43, -60, 60, 150.0f}}));
  ASSERT_LT(in.problem.clearance(from).distance, kBenchmarkLimits.clearance + 0.5);
  ASSERT_GT(in.problem.clearance(from).distance, kBenchmarkLimits.clearance);
  const StepOutput out = planner.step(in);
  EXPECT_EQ(out.mode, StepMode::kSolved) << out.reason;
}

TEST(VerticalMove, FromHoverToHoverWithinTheLimits) {
  for (const double rise : {0.5, 3.0, 15.0, 60.0, -10.0}) {
    const Vec3 from(10, -4, -30);
    const double speed = 1.2, accel = 0.4;
    const BsplineTrajectory climb = vertical_move(from, from.z() - rise, speed, accel);
    ASSERT_FALSE(climb.empty()) << rise;
    const double end = climb.duration();
    EXPECT_LT((climb.position(0) - from).norm(), 1e-9) << rise;
    EXPECT_LT((climb.position(end) - Vec3(10, -4, -30 - rise)).norm(), 1e-9) << rise;
    for (const double t : {0.0, end}) {
      EXPECT_LT(climb.velocity(t).norm(), 1e-9) << rise;
      EXPECT_LT(climb.acceleration(t).norm(), 1e-9) << rise;
    }
    double peak_speed = 0, peak_accel = 0, off_vertical = 0;
    for (int k = 0; k <= 1000; ++k) {
      const double t = end * k / 1000;
      peak_speed = std::max(peak_speed, climb.velocity(t).norm());
      peak_accel = std::max(peak_accel, climb.acceleration(t).norm());
      off_vertical = std::max(off_vertical, (climb.position(t) - from).head<2>().norm());
    }
    EXPECT_LE(peak_speed, speed * 1.001) << rise;
    EXPECT_LE(peak_accel, accel * 1.001) << rise;
    EXPECT_LT(off_vertical, 1e-9) << rise;
    // Not much slower than a bang-coast-bang move at the limits.
    const double d = std::abs(rise);
    const double fastest =
        d > speed * speed / accel ? d / speed + speed / accel : 2.0 * std::sqrt(d / accel);
    EXPECT_LT(end, 1.6 * fastest) << rise;
  }
  EXPECT_TRUE(vertical_move(Vec3(0, 0, -30), -30.0, 1.0, 1.0).empty());
}

// A hover before a wall at R_s plus a metre (the stack's dead-end hover):
// the climb straight up is committed step after step, and the same plan is
// flown throughout; from a moving state it brakes first.
TEST(RhPlannerClimb, FromAHoverBesideAWallTheClimbIsCommittedAndKept) {
  using testing_support::Box;
  RhPlanner planner(untimed());
  const Vec3 hover(40.5 - kBenchmarkLimits.clearance - 1.0, 0, -kLegAltitude);
  StepInput in = escape_leg(hover, hover, field_with({Box{40, 43, -60, 60, 150.0f}}));
  in.problem.velocity = Vec3::Zero();
  const double target_z = -(kLegAltitude + 15.0);
  const StepOutput first = planner.climb(in, target_z);
  ASSERT_EQ(first.mode, StepMode::kSolved) << first.reason;
  EXPECT_TRUE(first.commit.committed);
  EXPECT_NEAR(first.trajectory.position(first.trajectory.duration()).z(), target_z, 1e-9);
  EXPECT_NEAR(first.start_time, in.time, 1e-12);
  // Two seconds on, flying it: the same plan, from the same start.
  const double later = 2.0;
  in.time += later;
  in.problem.position = first.trajectory.position(later);
  in.problem.velocity = first.trajectory.velocity(later);
  in.problem.acceleration = first.trajectory.acceleration(later);
  const StepOutput next = planner.climb(in, target_z);
  ASSERT_EQ(next.mode, StepMode::kSolved) << next.reason;
  EXPECT_NEAR(next.start_time, first.start_time, 1e-12);
  EXPECT_NEAR(next.trajectory.duration(), first.trajectory.duration(), 1e-12);
  // A new planner, the vehicle still moving: a stop first.
  RhPlanner fresh;
  StepInput moving = escape_leg(hover, hover, field_with({}));
  moving.problem.velocity = Vec3(-0.5, 0, 0);
  EXPECT_EQ(fresh.climb(moving, target_z).mode, StepMode::kBraking);
}

// Something mapped above the hover (no obstacle in the grid stands in the
// air, but the gate does not rely on it): the climb is flown until its stop
// would come nearer than the gate allows, then the vehicle brakes.
TEST(RhPlannerClimb, AClimbIntoSomethingMappedAboveIsRefusedInTime) {
  const double roof_z = -(kLegAltitude + 6.0);  // 6 m above the hover
  ClearanceQuery roof = [roof_z](const Vec3& p) {
    mapping::DistanceSample d;
    d.distance = std::max(0.0, p.z() - roof_z);  // up is -z
    d.gradient = Vec3(0, 0, 1);
    return d;
  };
  RhPlanner planner(untimed());
  const Vec3 hover(0, 0, -(kLegAltitude - 8.0));  // 14 m under the roof
  StepInput in = escape_leg(hover, hover, roof);
  in.problem.velocity = Vec3::Zero();
  const double target_z = -(kLegAltitude + 20.0);
  const StepOutput first = planner.climb(in, target_z);
  ASSERT_EQ(first.mode, StepMode::kSolved) << first.reason;
  const BsplineTrajectory plan = first.trajectory;
  bool braked = false;
  for (double t = 0.1; t <= plan.duration() && !braked; t += 0.1) {
    in.time = first.start_time + t;
    in.problem.position = plan.position(t);
    in.problem.velocity = plan.velocity(t);
    in.problem.acceleration = plan.acceleration(t);
    const StepOutput out = planner.climb(in, target_z);
    if (out.mode != StepMode::kBraking) continue;
    braked = true;
    EXPECT_NE(out.reason.find("refused the climb"), std::string::npos) << out.reason;
    double highest = 0;  // m above the hover the stop reaches
    for (int k = 0; k <= 200; ++k)
      highest = std::max(
          highest, hover.z() - out.trajectory.position(out.trajectory.duration() * k / 200.0).z());
    EXPECT_LE(hover.z() - roof_z - highest + 1e-6, 14.0);
    EXPECT_GE(14.0 - highest, 0.9 * kBenchmarkLimits.clearance - 0.05) << "at t=" << t;
  }
  EXPECT_TRUE(braked);
}

}  // namespace
}  // namespace ofn::rh

namespace ofn::rh {
namespace {

// The mission leg: north from the origin, at 36.6 m.
const GuidanceFrame kLegFrame = GuidanceFrame::from_leg(Vec3(0, 0, -36.6), Vec3(150, 0, -36.6));

RecoverySettings settings() {
  RecoverySettings s;
  s.stuck_time = 4.0;
  s.route_wait = 3.0;
  s.route_timeout = 10.0;
  s.max_attempts = 2;
  return s;
}

// One recovery, fed at 10 Hz from a hovering vehicle whose heading the
// test turns.
class RecoveryRun {
 public:
  explicit RecoveryRun(RecoverySettings s = settings()) : recovery(s) {
    in.engaged = true;
    in.position = Vec3(80, 0, -36.6);
    in.altitude = 36.6;
    in.max_vertical_speed = 1.5;
    in.leg = kLegFrame;
    in.route_points = &route;
  }
  RecoveryDecision step(double dt = 0.1) {
    in.time += dt;
    RecoveryDecision d = recovery.update(in);
    if (d.changed) last_reason = d.reason;
    return d;
  }
  /// Steps for `seconds`, turning the heading at `yaw_rate`.
  RecoveryDecision run(double seconds, double yaw_rate = 0.0) {
    RecoveryDecision d;
    for (double t = 0; t < seconds - 1e-9; t += 0.1) {
      in.yaw = wrap_angle(in.yaw + yaw_rate * 0.1);
      d = step();
    }
    return d;
  }
  /// Turns the way the recovery says, at 0.5 rad/s, until it leaves `phase`
  /// (at most `limit` s); `turned` gets the time it took.
  RecoveryDecision turn_out_of(RecoveryPhase phase, double limit = 60.0, double* took = nullptr) {
    RecoveryDecision d = recovery.update(in);
    double t = 0;
    for (; t < limit && recovery.phase() == phase; t += 0.1) {
      in.yaw = wrap_angle(in.yaw + (d.turn_left ? -0.5 : 0.5) * 0.1);
      d = step();
    }
    if (took) *took = t;
    return d;
  }
  void give_route(RouteKind kind, std::vector<Vec3> points) {
    in.route = kind;
    in.route_time = in.time;
    route = std::move(points);
  }
  /// A look from start to end: a full turn at 0.5 rad/s, then the planner's
  /// route made after it, then the recovery's wait for it.
  RecoveryDecision look_finds(RouteKind kind, std::vector<Vec3> points = {}) {
    run(2 * M_PI / 0.5 + 0.3, 0.5);
    give_route(kind, std::move(points));
    return run(3.1);
  }

  DeadEndRecovery recovery;
  RecoveryInput in;
  std::vector<Vec3> route;
  std::string last_reason;  // of the last phase change
};

// A route out of a U whose opening is behind the vehicle: back south, then
// east round the side wall, then north along it (2 m spacing).
std::vector<Vec3> route_out_of_the_u(const Vec3& from) {
  const std::vector<Vec3> corners = {from, Vec3(20, 0, -36.6), Vec3(20, 45, -36.6),
                                     Vec3(100, 45, -36.6), Vec3(150, 0, -36.6)};
  std::vector<Vec3> points{corners.front()};
  for (size_t k = 1; k < corners.size(); ++k) {
    const Vec3 a = corners[k - 1], b = corners[k];
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / 2.0)));
    for (int i = 1; i <= n; ++i) points.push_back(a + (b - a) * (double(i) / n));
  }
  return points;
}

// The verdict knows an escape by its mark; a blind step in the middle of an
// escape (the map starved, the controller flying the escape's stop) keeps
// it, or the escape's backward flight would be judged as a forward leg's.
TEST(RecoveryMessage, MarksEveryStepOfAnEscapeOnce) {
  EXPECT_EQ(recovery_message(RecoveryPhase::kEscaping, "solved"), "escaping: solved");
  EXPECT_EQ(recovery_message(RecoveryPhase::kEscaping, "map starved of scans: 17 %"),
            "escaping: map starved of scans: 17 %");
  EXPECT_EQ(recovery_message(RecoveryPhase::kEscaping, "escaping: braking"), "escaping: braking");
  EXPECT_EQ(recovery_message(RecoveryPhase::kClimbing, "solved: climbing"),
            "climbing: solved: climbing");
  EXPECT_EQ(recovery_message(RecoveryPhase::kClimbing, "climbing: braking"), "climbing: braking");
  for (RecoveryPhase other : {RecoveryPhase::kIdle, RecoveryPhase::kLooking,
                              RecoveryPhase::kTurning, RecoveryPhase::kNoRoute})
    EXPECT_EQ(recovery_message(other, "nav stale"), "nav stale") << to_string(other);
}

TEST(DeadEndRecovery, LooksAroundOnlyAfterHoveringWithoutAPlanForTheStuckTime) {
  RecoveryRun r;
  EXPECT_EQ(r.run(3.9).phase, RecoveryPhase::kIdle);
  const RecoveryDecision d = r.run(0.2);
  EXPECT_EQ(d.phase, RecoveryPhase::kLooking);
  EXPECT_EQ(r.recovery.attempts(), 1);

  // A plan that moves off, or a vehicle that moves, is not stuck.
  RecoveryRun moving;
  moving.in.moving_plan = true;
  EXPECT_EQ(moving.run(10).phase, RecoveryPhase::kIdle);
  RecoveryRun flying;
  flying.in.velocity = Vec3(1.0, 0, 0);
  EXPECT_EQ(flying.run(10).phase, RecoveryPhase::kIdle);
  // Nor is one that waypoint guidance flies.
  RecoveryRun guided;
  guided.in.engaged = false;
  EXPECT_EQ(guided.run(10).phase, RecoveryPhase::kIdle);
}

// A livelock (dense seed 18 over a bad link hovered 57 s so): every step
// commits a plan that moves off, the next replaces it before the vehicle
// has gone anywhere. The vehicle's own progress decides, not the plans'.
TEST(DeadEndRecovery, AVehicleThatStaysPutIsStuckWhateverThePlansSay) {
  RecoveryRun r;
  r.in.moving_plan = true;
  r.in.velocity = Vec3(0.2, 0, 0);  // drifting about the spot, below the hover speed
  EXPECT_EQ(r.run(19.8).phase, RecoveryPhase::kIdle);
  RecoveryDecision d = r.step();
  if (!d.changed) d = r.step();
  if (!d.changed) d = r.step();
  EXPECT_EQ(d.phase, RecoveryPhase::kLooking);
  EXPECT_NE(d.reason.find("no progress"), std::string::npos) << d.reason;

  // Slow flight that gets somewhere is progress: 0.25 m/s for a minute.
  RecoveryRun slow;
  slow.in.moving_plan = true;
  slow.in.velocity = Vec3(0.25, 0, 0);
  for (int k = 0; k < 600; ++k) {
    slow.in.position.x() += 0.025;
    ASSERT_EQ(slow.step().phase, RecoveryPhase::kIdle) << "at " << slow.in.time << " s";
  }
  // And the spot is forgotten when guidance takes over: 15 s engaged, 1 s
  // not, 15 s engaged again at the same spot is not stuck.
  RecoveryRun interrupted;
  interrupted.in.moving_plan = true;
  interrupted.run(15);
  interrupted.in.engaged = false;
  interrupted.run(1);
  interrupted.in.engaged = true;
  EXPECT_EQ(interrupted.run(15).phase, RecoveryPhase::kIdle);
}

TEST(DeadEndRecovery, TheLookEndsAfterAFullTurnAndARouteMadeSince) {
  RecoveryRun r;
  r.run(4.1);
  ASSERT_EQ(r.recovery.phase(), RecoveryPhase::kLooking);
  // Half a turn and a route: still looking.
  r.give_route(RouteKind::kForward, {r.in.position, Vec3(150, 0, -36.6)});
  EXPECT_EQ(r.run(2 * M_PI / 0.5 / 2, 0.5).phase, RecoveryPhase::kLooking);
  // The rest of the turn; a route older than the look's end is not taken.
  r.run(2 * M_PI / 0.5 / 2 + 0.2, 0.5);
  EXPECT_EQ(r.run(5).phase, RecoveryPhase::kLooking);
  // A route made after the look, heading along the leg: turn to face the
  // leg (north), then normal planning.
  r.give_route(RouteKind::kForward, {r.in.position, Vec3(150, 0, -36.6)});
  r.in.yaw = 2.0;
  EXPECT_EQ(r.run(0.1).phase, RecoveryPhase::kTurning);
  const RecoveryDecision d = r.turn_out_of(RecoveryPhase::kTurning);
  EXPECT_EQ(d.phase, RecoveryPhase::kIdle);
  EXPECT_LE(std::abs(wrap_angle(r.in.yaw)), settings().face_tolerance + 0.05);
}

TEST(DeadEndRecovery, ATurnToTheWayOnTakesTheShorterWay) {
  // Looks turn to the right; a turn to face the way on turns whichever way
  // is shorter: a quarter turn, not three quarters (12 s more at 30 deg/s).
  for (const double start_yaw : {1.2, -1.2}) {
    RecoveryRun r;
    const RecoveryDecision look = r.run(4.1);
    ASSERT_EQ(look.phase, RecoveryPhase::kLooking);
    EXPECT_FALSE(look.turn_left);
    r.run(2 * M_PI / 0.5 + 0.3, 0.5);
    r.give_route(RouteKind::kForward, {r.in.position, Vec3(150, 0, -36.6)});
    r.in.yaw = start_yaw;  // the leg is north: turn back to yaw 0
    const RecoveryDecision turn = r.run(3.1);
    ASSERT_EQ(turn.phase, RecoveryPhase::kTurning) << start_yaw;
    EXPECT_EQ(turn.turn_left, start_yaw > 0) << start_yaw;
    double took = 0;
    EXPECT_EQ(r.turn_out_of(RecoveryPhase::kTurning, 60.0, &took).phase, RecoveryPhase::kIdle);
    // (1.2 - face_tolerance) / 0.5 rad/s, then face_hold.
    const double shorter = (1.2 - settings().face_tolerance) / 0.5 + settings().face_hold;
    EXPECT_LE(took, shorter + 0.3) << start_yaw;
  }
}

TEST(DeadEndRecovery, EscapesLegByLegAlongARouteThatTurnsBack) {
  RecoveryRun r;
  r.run(4.1);
  r.run(2 * M_PI / 0.5 + 0.3, 0.5);  // the look
  r.give_route(RouteKind::kBacktrack, route_out_of_the_u(r.in.position));
  r.run(3.1);
  ASSERT_EQ(r.recovery.phase(), RecoveryPhase::kTurning);
  // The first leg ends at the first corner, (20, 0): facing south first.
  RecoveryDecision d = r.turn_out_of(RecoveryPhase::kTurning);
  ASSERT_EQ(d.phase, RecoveryPhase::kEscaping);
  EXPECT_LT((d.escape_point - Vec3(20, 0, -36.6)).norm(), 1e-9);
  EXPECT_LT(std::abs(wrap_angle(r.in.yaw - M_PI)), settings().face_tolerance + 0.05);
  ASSERT_FALSE(d.escape_route.empty());
  EXPECT_LT((d.escape_route.back() - d.escape_point).norm(), 1e-9);
  // Flying it is not being stuck.
  r.in.velocity = Vec3(-1.5, 0, 0);
  EXPECT_EQ(r.run(10).phase, RecoveryPhase::kEscaping);
  // At the corner, at rest: the route from there (it starts at the vehicle)
  // gives the next leg, east to (20, 45), after which the route heads north.
  r.in.position = Vec3(20.5, 0, -36.6);
  r.in.velocity = Vec3::Zero();
  r.give_route(RouteKind::kBacktrack, route_out_of_the_u(r.in.position));
  d = r.step();
  ASSERT_EQ(d.phase, RecoveryPhase::kTurning);
  d = r.turn_out_of(RecoveryPhase::kTurning);
  ASSERT_EQ(d.phase, RecoveryPhase::kEscaping);
  EXPECT_LT((d.escape_point - Vec3(20, 45, -36.6)).norm(), 1e-9);
  EXPECT_EQ(r.recovery.attempts(), 0);  // a leg done counts as progress
  // There, the route heads along the leg: face north, then normal planning.
  r.in.position = Vec3(20, 44, -36.6);
  r.give_route(RouteKind::kForward, {r.in.position, Vec3(100, 45, -36.6), Vec3(150, 0, -36.6)});
  EXPECT_EQ(r.step().phase, RecoveryPhase::kTurning);
  EXPECT_EQ(r.turn_out_of(RecoveryPhase::kTurning).phase, RecoveryPhase::kIdle);
}

TEST(DeadEndRecovery, NoRouteAfterTheLookHoldsTheHoverAndSaysSo) {
  RecoverySettings never_climbs = settings();
  never_climbs.climb_step = 0.0;
  RecoveryRun r(never_climbs);
  r.run(4.1);
  RecoveryDecision d = r.look_finds(RouteKind::kNoPath);
  EXPECT_EQ(d.phase, RecoveryPhase::kNoRoute);
  EXPECT_EQ(r.run(30).phase, RecoveryPhase::kNoRoute);
  // No route heard at all after the look: no route too, at the timeout.
  RecoveryRun silent;
  silent.run(4.1);
  silent.run(2 * M_PI / 0.5 + 0.3, 0.5);
  EXPECT_EQ(silent.run(9.5).phase, RecoveryPhase::kLooking);
  EXPECT_EQ(silent.run(0.6).phase, RecoveryPhase::kNoRoute);
  // A route that appears later (the map changed) is taken up.
  r.give_route(RouteKind::kBacktrack, route_out_of_the_u(r.in.position));
  EXPECT_EQ(r.step().phase, RecoveryPhase::kTurning);
}

// A route after the look through a passage too narrow to fly (the service
// tells the global planner): the recovery waits for the planner's next
// route, asking once per route, and takes that one.
TEST(DeadEndRecovery, ARouteThroughANarrowPassageWaitsForTheNextRoute) {
  RecoveryRun r;
  r.run(4.1);
  int asked = 0;
  r.in.route_flyable = [&] {
    ++asked;
    return asked > 1;  // the first route runs through a pinch
  };
  RecoveryDecision d = r.look_finds(RouteKind::kBacktrack, route_out_of_the_u(r.in.position));
  EXPECT_EQ(d.phase, RecoveryPhase::kLooking);
  EXPECT_EQ(asked, 1);
  EXPECT_EQ(r.run(2.0).phase, RecoveryPhase::kLooking);
  EXPECT_EQ(asked, 1);  // the same route is not asked about again
  r.give_route(RouteKind::kBacktrack, route_out_of_the_u(r.in.position));
  EXPECT_EQ(r.step().phase, RecoveryPhase::kTurning);
  EXPECT_EQ(asked, 2);
  // NO_PATH is never asked about: the climb (or no route) follows at once.
  RecoveryRun none;
  none.run(4.1);
  none.in.route_flyable = [&] {
    ADD_FAILURE() << "asked about NO_PATH";
    return false;
  };
  EXPECT_NE(none.look_finds(RouteKind::kNoPath).phase, RecoveryPhase::kLooking);
  // Nothing newer within route_timeout of the look: no route, as with none.
  RecoveryRun waits;
  waits.run(4.1);
  waits.in.route_flyable = [] { return false; };
  waits.look_finds(RouteKind::kForward, {waits.in.position, waits.in.position + Vec3(50, 0, 0)});
  EXPECT_EQ(waits.run(6.4).phase, RecoveryPhase::kLooking);
  EXPECT_EQ(waits.run(0.6).phase, RecoveryPhase::kNoRoute);
}

TEST(DeadEndRecovery, AnEscapeStuckTooOftenEndsInNoRoute) {
  RecoveryRun r;  // max_attempts 2
  for (int attempt = 1; attempt <= 2; ++attempt) {
    r.run(4.1);
    ASSERT_EQ(r.recovery.phase(), RecoveryPhase::kLooking) << attempt;
    EXPECT_EQ(r.recovery.attempts(), attempt);
    r.run(2 * M_PI / 0.5 + 0.3, 0.5);
    r.give_route(RouteKind::kBacktrack, route_out_of_the_u(r.in.position));
    r.run(3.1);
    ASSERT_EQ(r.turn_out_of(RecoveryPhase::kTurning).phase, RecoveryPhase::kEscaping);
    // No plan moves off: stuck again.
  }
  EXPECT_EQ(r.run(4.1).phase, RecoveryPhase::kNoRoute);
  EXPECT_EQ(r.run(60).phase, RecoveryPhase::kNoRoute);
  // The hand-back to guidance ends it all.
  r.in.engaged = false;
  EXPECT_EQ(r.step().phase, RecoveryPhase::kIdle);
  EXPECT_EQ(r.recovery.attempts(), 0);
}

// Looks that find no route climb by climb_step, up to the ceiling; there,
// no route. Each climb done counts as progress (the looks count from none).
TEST(DeadEndRecovery, NoRouteAfterTheLookClimbsToLookAgainUpToTheCeiling) {
  RecoverySettings s = settings();
  s.climb_step = 15.0;
  s.climb_ceiling = 60.0;
  RecoveryRun r(s);
  r.run(4.1);
  RecoveryDecision d = r.look_finds(RouteKind::kNoPath);
  ASSERT_EQ(d.phase, RecoveryPhase::kClimbing) << r.last_reason;
  EXPECT_NEAR(d.climb_altitude, 51.6, 1e-9);
  EXPECT_NE(r.last_reason.find("climbing from 36.6 to 51.6 m"), std::string::npos) << r.last_reason;
  // Under way (the planner still says no path, periodically): still climbing.
  r.in.velocity = Vec3(0, 0, -1.2);
  r.in.altitude = 45.0;
  r.give_route(RouteKind::kNoPath, {});
  EXPECT_EQ(r.run(5).phase, RecoveryPhase::kClimbing);
  // There, at rest: a look from the new altitude, the first of a new count.
  r.in.velocity = Vec3::Zero();
  r.in.altitude = 51.3;
  d = r.step();
  ASSERT_EQ(d.phase, RecoveryPhase::kLooking) << r.last_reason;
  EXPECT_EQ(r.recovery.attempts(), 1);
  // No route from there either: the next climb stops at the ceiling.
  d = r.look_finds(RouteKind::kNoPath);
  ASSERT_EQ(d.phase, RecoveryPhase::kClimbing);
  EXPECT_NEAR(d.climb_altitude, 60.0, 1e-9);
  r.in.altitude = 59.8;
  ASSERT_EQ(r.step().phase, RecoveryPhase::kLooking);
  d = r.look_finds(RouteKind::kNoPath);
  EXPECT_EQ(d.phase, RecoveryPhase::kNoRoute);
  EXPECT_EQ(r.run(30).phase, RecoveryPhase::kNoRoute);
}

// The climb turns the heading (LOOK_AROUND): one that turned all round on
// the way up has seen what a look at its altitude would show, and only the
// route is waited for; one that did not turn needs the look.
TEST(DeadEndRecovery, AClimbThatTurnedAllRoundNeedsNoLookAfterIt) {
  // Rest to rest: the climb stops at its step (climb_through passes it).
  RecoverySettings s = settings();
  s.climb_through = false;
  for (const bool turning : {true, false}) {
    RecoveryRun r(s);
    r.run(4.1);
    ASSERT_EQ(r.look_finds(RouteKind::kNoPath).phase, RecoveryPhase::kClimbing);
    r.in.velocity = Vec3(0, 0, -1.2);
    r.run(2 * M_PI / 0.5 + 0.3, turning ? 0.5 : 0.0);
    ASSERT_EQ(r.recovery.phase(), RecoveryPhase::kClimbing);
    r.in.velocity = Vec3::Zero();
    r.in.altitude = 51.5;
    ASSERT_EQ(r.step().phase, RecoveryPhase::kLooking);
    EXPECT_EQ(r.last_reason.find("the look is done") != std::string::npos, turning)
        << r.last_reason;
    r.give_route(RouteKind::kForward, {r.in.position, Vec3(150, 0, -51.5)});
    EXPECT_EQ(r.run(3.1).phase, turning ? RecoveryPhase::kTurning : RecoveryPhase::kLooking)
        << "turning on the way up: " << turning;
  }
}

TEST(DeadEndRecovery, ARouteFoundOnTheWayUpIsTakenAtOnce) {
  RecoveryRun r;
  r.run(4.1);
  ASSERT_EQ(r.look_finds(RouteKind::kNoPath).phase, RecoveryPhase::kClimbing);
  r.in.velocity = Vec3(0, 0, -1.2);
  r.in.altitude = 42.0;
  r.give_route(RouteKind::kForward, {r.in.position, Vec3(150, 0, -42.0)});
  EXPECT_EQ(r.step().phase, RecoveryPhase::kTurning);
}

// A climb the commit gate refuses leaves the vehicle hovering where it was:
// after the time a climb may take, a look; the looks then count on to "no
// route", so refused climbs cannot go on for ever.
TEST(DeadEndRecovery, AClimbThatDoesNotProceedEndsInNoRoute) {
  RecoveryRun r;  // max_attempts 2
  r.run(4.1);
  ASSERT_EQ(r.look_finds(RouteKind::kNoPath).phase, RecoveryPhase::kClimbing);
  const double allowed = settings().climb_step / 1.5 + settings().climb_extra_time;
  EXPECT_EQ(r.run(allowed - 0.5).phase, RecoveryPhase::kClimbing);
  RecoveryDecision d = r.run(0.6);
  ASSERT_EQ(d.phase, RecoveryPhase::kLooking);
  EXPECT_NE(r.last_reason.find("the climb stopped at 36.6 m"), std::string::npos) << r.last_reason;
  EXPECT_EQ(r.recovery.attempts(), 2);
  ASSERT_EQ(r.look_finds(RouteKind::kNoPath).phase, RecoveryPhase::kClimbing);
  EXPECT_EQ(r.run(allowed + 0.1).phase, RecoveryPhase::kNoRoute);
}

// With climb_through the climb is flown to the ceiling and passes each step
// once the heading has turned all round: no hover, no wait at the step;
// a step passed before the turn is done is passed when it is.
TEST(DeadEndRecovery, AClimbThroughPassesEachStepOnceTheLookIsDone) {
  RecoverySettings s = settings();
  s.climb_step = 15.0;
  s.climb_ceiling = 80.0;
  s.climb_through = true;
  RecoveryRun r(s);
  r.run(4.1);
  RecoveryDecision d = r.look_finds(RouteKind::kNoPath);
  ASSERT_EQ(d.phase, RecoveryPhase::kClimbing) << r.last_reason;
  EXPECT_NEAR(d.climb_altitude, 51.6, 1e-9);
  EXPECT_NEAR(d.climb_target, 80.0, 1e-9);  // the plan flown goes to the ceiling
  // Past the step at speed, the heading not yet all round: climbing on to
  // the same step.
  r.in.velocity = Vec3(0, 0, -1.2);
  r.in.altitude = 52.0;
  d = r.run(5.0, 0.5);
  ASSERT_EQ(d.phase, RecoveryPhase::kClimbing);
  EXPECT_NEAR(d.climb_altitude, 51.6, 1e-9);
  // The turn completes: the next step, the looks counted from none, the
  // ceiling still the target; no look, no hover.
  d = r.run(2 * M_PI / 0.5 - 5.0 + 0.3, 0.5);
  ASSERT_EQ(d.phase, RecoveryPhase::kClimbing) << r.last_reason;
  EXPECT_NEAR(d.climb_altitude, 66.6, 1e-9);
  EXPECT_NEAR(d.climb_target, 80.0, 1e-9);
  EXPECT_EQ(r.recovery.attempts(), 0);
  EXPECT_NE(r.last_reason.find("on to 66.6 m"), std::string::npos) << r.last_reason;
  // A route made on the way is taken at once.
  r.in.altitude = 60.0;
  r.give_route(RouteKind::kForward, {r.in.position, Vec3(150, 0, -60.0)});
  EXPECT_EQ(r.step().phase, RecoveryPhase::kTurning);
}

TEST(DeadEndRecovery, AClimbThroughEndsAtTheCeilingWithALook) {
  RecoverySettings s = settings();
  s.climb_step = 15.0;
  s.climb_ceiling = 60.0;
  s.climb_through = true;
  RecoveryRun r(s);
  r.run(4.1);
  ASSERT_EQ(r.look_finds(RouteKind::kNoPath).phase, RecoveryPhase::kClimbing);
  r.in.velocity = Vec3(0, 0, -1.2);
  r.in.altitude = 52.0;
  RecoveryDecision d = r.run(2 * M_PI / 0.5 + 0.3, 0.5);
  ASSERT_EQ(d.phase, RecoveryPhase::kClimbing);
  EXPECT_NEAR(d.climb_altitude, 60.0, 1e-9);  // the last step is the ceiling
  EXPECT_NEAR(d.climb_target, 60.0, 1e-9);
  r.in.velocity = Vec3::Zero();
  r.in.altitude = 59.8;
  ASSERT_EQ(r.step().phase, RecoveryPhase::kLooking) << r.last_reason;
  EXPECT_EQ(r.look_finds(RouteKind::kNoPath).phase, RecoveryPhase::kNoRoute);
}

// Without climb_through each climb is flown to its step and stops there.
TEST(DeadEndRecovery, AClimbRestToRestFliesToItsStep) {
  RecoverySettings s = settings();
  s.climb_through = false;
  RecoveryRun r(s);
  r.run(4.1);
  const RecoveryDecision d = r.look_finds(RouteKind::kNoPath);
  ASSERT_EQ(d.phase, RecoveryPhase::kClimbing);
  EXPECT_NEAR(d.climb_target, d.climb_altitude, 1e-9);
}

// skip_turn_when_seen: from a hover, an escape leg whose way the scanner
// has seen starts at once; one into unseen space, or any leg while the
// vehicle still moves, waits for the turn to face it.
TEST(DeadEndRecovery, AnEscapeWhoseWayIsSeenStartsWithoutTheTurn) {
  for (const bool seen : {true, false}) {
    RecoverySettings s = settings();
    s.skip_turn_when_seen = true;
    RecoveryRun r(s);
    int asked = 0;
    r.in.way_seen = [&](const Vec3& from, const Vec3& to) {
      ++asked;
      EXPECT_LT((from - r.in.position).norm(), 1e-9);
      EXPECT_LT((to - Vec3(20, 0, -36.6)).norm(), 1e-9);  // the first corner
      return seen;
    };
    r.run(4.1);
    r.run(2 * M_PI / 0.5 + 0.3, 0.5);  // the look; the heading ends about north
    r.give_route(RouteKind::kBacktrack, route_out_of_the_u(r.in.position));
    const RecoveryDecision d = r.run(3.1);
    EXPECT_EQ(asked, 1);
    ASSERT_EQ(d.phase, seen ? RecoveryPhase::kEscaping : RecoveryPhase::kTurning)
        << "seen " << seen << ": " << r.last_reason;
    if (seen) {
      EXPECT_LT((d.escape_point - Vec3(20, 0, -36.6)).norm(), 1e-9);
      EXPECT_LT((d.escape_from - r.in.position).norm(), 1e-9);
      EXPECT_FALSE(d.escape_route.empty());
    }
  }
  // Off (the default), or moving: the turn, whatever is seen.
  for (const bool moving : {false, true}) {
    RecoverySettings s = settings();
    s.skip_turn_when_seen = moving;
    RecoveryRun r(s);
    r.in.way_seen = [](const Vec3&, const Vec3&) { return true; };
    r.run(4.1);
    r.run(2 * M_PI / 0.5 + 0.3, 0.5);
    r.give_route(RouteKind::kBacktrack, route_out_of_the_u(r.in.position));
    if (moving) r.in.velocity = Vec3(0.5, 0, 0);
    r.run(3.1);
    EXPECT_EQ(r.recovery.phase(), RecoveryPhase::kTurning) << "moving " << moving;
  }
}

TEST(DeadEndRecovery, DisabledItNeverActs) {
  RecoverySettings s = settings();
  s.enabled = false;
  RecoveryRun r(s);
  EXPECT_EQ(r.run(60).phase, RecoveryPhase::kIdle);
}

TEST(DeadEndRecovery, RouteShapes) {
  const Vec3 a(80, 0, -36.6);
  const std::vector<Vec3> out_of_u = route_out_of_the_u(a);
  // The route heads along the leg from (20, 45) on; its first corner is (20, 0).
  const auto forward = forward_from(out_of_u, kLegFrame);
  ASSERT_TRUE(forward);
  EXPECT_LT((out_of_u[*forward] - Vec3(20, 45, -36.6)).norm(), 1e-9);
  const auto leg_end = escape_leg_end(out_of_u, kLegFrame);
  ASSERT_TRUE(leg_end);
  EXPECT_LT((out_of_u[*leg_end] - Vec3(20, 0, -36.6)).norm(), 1e-9);
  // A route straight on heads along the leg from its start.
  EXPECT_EQ(forward_from({a, Vec3(100, 5, -36.6), Vec3(150, 0, -36.6)}, kLegFrame), size_t{0});
  // Too short to say.
  EXPECT_FALSE(forward_from({a}, kLegFrame));
}

}  // namespace
}  // namespace ofn::rh
