// Flight figures of merit (gate timing, speeds, tracking error, the
// controller's command and the reference's continuity) and the verdict.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "ofn/control_status_t.hpp"
#include "ofn/tools/flight_analysis.hpp"

namespace ofn::report {
namespace {

NavSample nav(double t, double north, Vec3 velocity = Vec3(10, 0, 0)) {
  NavSample s;
  s.t = t;
  s.position = Vec3(north, 0, -30);
  s.velocity = velocity;
  s.acceleration = Vec3::Zero();
  s.euler = Vec3::Zero();
  s.body_rates = Vec3::Zero();
  return s;
}

StatusSample status(double t, int mode, Vec3 error, Vec3 ref_accel = Vec3::Zero(),
                    Vec3 commanded = Vec3::Zero()) {
  StatusSample s;
  s.t = t;
  s.mode = mode;
  s.ref_position = Vec3::Zero();
  s.ref_velocity = Vec3::Zero();
  s.ref_acceleration = ref_accel;
  s.commanded_accel = commanded;
  s.position_error = error;
  return s;
}

/// 10 m/s north from x = -100 m to x = 500 m, sampled at 10 Hz.
std::vector<NavSample> straight_run() {
  std::vector<NavSample> out;
  for (int i = 0; i <= 600; ++i) out.push_back(nav(0.1 * i, -100.0 + 1.0 * i));
  return out;
}

Limits limits() {
  Limits l;
  l.max_speed = 12;
  l.max_accel = 0.5;
  l.max_vertical_speed = 2;
  return l;
}

TEST(CrossingTime, InterpolatesBetweenSamples) {
  const std::vector<NavSample> samples = {nav(0.0, 0.0), nav(1.0, 10.0), nav(2.0, 30.0)};
  ASSERT_TRUE(crossing_time(samples, 5.0).has_value());
  EXPECT_NEAR(*crossing_time(samples, 5.0), 0.5, 1e-12);
  EXPECT_NEAR(*crossing_time(samples, 15.0), 1.25, 1e-12);
  EXPECT_NEAR(*crossing_time(samples, 10.0), 1.0, 1e-12);  // exactly on a sample
  EXPECT_NEAR(*crossing_time(samples, 30.0), 2.0, 1e-12);  // the last sample
}

TEST(CrossingTime, NeverReachedOrStartedPastIsNothing) {
  const std::vector<NavSample> samples = {nav(0.0, 0.0), nav(1.0, 10.0), nav(2.0, 30.0)};
  EXPECT_FALSE(crossing_time(samples, 31.0).has_value());
  EXPECT_FALSE(crossing_time(samples, -5.0).has_value());
  EXPECT_FALSE(crossing_time({}, 0.0).has_value());
  EXPECT_FALSE(crossing_time({nav(0.0, 0.0)}, 0.0).has_value());
}

TEST(CrossingTime, FirstCrossingCounts) {
  // Forward past 10, back, and forward again: the first crossing is timed.
  const std::vector<NavSample> samples = {nav(0, 0), nav(1, 20), nav(2, 0), nav(3, 20)};
  EXPECT_NEAR(*crossing_time(samples, 10.0), 0.5, 1e-12);
}

// The controller as shipped: collective, longitudinal and lateral cyclic, pedal.
const ControlStops kStops{{-0.05, -0.16, -0.16, -0.40}, {0.30, 0.16, 0.16, 0.40}};

TEST(ControlSaturation, SharesOfCommandsAtAStopPerChannelAndTogether) {
  const std::vector<std::array<double, 4>> commands = {
      {0.10, 0.00, 0.00, 0.00},    // inside every stop
      {0.10, 0.16, 0.00, 0.00},    // longitudinal cyclic at its upper stop
      {0.10, 0.00, -0.16, 0.00},   // lateral cyclic at its lower stop
      {0.10, -0.16, 0.159, 0.0},   // both cyclics (0.159 is within 0.5 % of the range)
      {0.30, 0.00, 0.00, -0.40},   // collective and pedal, no cyclic
      {0.10, 0.155, 0.00, 0.00}};  // 0.005 short of the stop: not at it
  const ControlSaturation c = control_saturation(commands, kStops);
  EXPECT_EQ(c.samples, 6u);
  EXPECT_DOUBLE_EQ(c.share[0], 1.0 / 6.0);
  EXPECT_DOUBLE_EQ(c.share[1], 2.0 / 6.0);
  EXPECT_DOUBLE_EQ(c.share[2], 2.0 / 6.0);
  EXPECT_DOUBLE_EQ(c.share[3], 1.0 / 6.0);
  EXPECT_DOUBLE_EQ(c.cyclic_share, 3.0 / 6.0);
  EXPECT_DOUBLE_EQ(c.any_share, 4.0 / 6.0);
}

TEST(ControlSaturation, NoCommandsAndNonFiniteOnesAreAtNoStop) {
  const ControlSaturation none = control_saturation({}, kStops);
  EXPECT_EQ(none.samples, 0u);
  EXPECT_EQ(none.any_share, 0.0);
  const double nan = std::nan("");
  const ControlSaturation bad = control_saturation({{nan, nan, nan, nan}}, kStops);
  EXPECT_EQ(bad.samples, 1u);
  EXPECT_EQ(bad.any_share, 0.0);
}

TEST(AnalyseFlight, GateToGateAtTenMetresPerSecond) {
  const auto samples = straight_run();
  const FlightSummary s = analyse_flight(samples, {}, limits(), 0.0, 400.0);
  ASSERT_TRUE(s.gate_start_time.has_value());
  ASSERT_TRUE(s.gate_finish_time.has_value());
  ASSERT_TRUE(s.gate_to_gate.has_value());
  EXPECT_NEAR(*s.gate_start_time, 10.0, 1e-9);
  EXPECT_NEAR(*s.gate_finish_time, 50.0, 1e-9);
  EXPECT_NEAR(*s.gate_to_gate, 40.0, 1e-9);
  EXPECT_TRUE(s.crossed_finish);
  EXPECT_NEAR(s.duration, 60.0, 1e-9);
  EXPECT_NEAR(s.max_speed, 10.0, 1e-12);
  EXPECT_NEAR(s.max_vertical_speed, 0.0, 1e-12);
  EXPECT_FALSE(s.reached_last_waypoint);
}

// Backing out of a dead end flies south on purpose: the forward-speed rule
// is relaxed there, and only there (plus the settling time after it).
TEST(AnalyseFlight, ForwardSpeedIsNotCountedInADeadEndRecovery) {
  auto samples = straight_run();
  for (auto& n : samples)
    if (n.t >= 20.0 && n.t <= 22.0) n.velocity = Vec3(-1.0, 0, 0);
  EXPECT_NEAR(analyse_flight(samples, {}, limits(), 0.0, 400.0).min_forward_speed, -1.0, 1e-12);
  const FlightSummary s = analyse_flight(samples, {}, limits(), 0.0, 400.0, {TimeSpan{19.0, 20.5}});
  EXPECT_NEAR(s.min_forward_speed, 10.0, 1e-12);
  EXPECT_NEAR(s.recovery_time, 1.5, 1e-12);
  // A span that ends long before does not cover it.
  EXPECT_NEAR(
      analyse_flight(samples, {}, limits(), 0.0, 400.0, {TimeSpan{12.0, 14.0}}).min_forward_speed,
      -1.0, 1e-12);
}

TEST(AnalyseFlight, GateBetweenSamplesIsInterpolated) {
  const auto samples = straight_run();
  const FlightSummary s = analyse_flight(samples, {}, limits(), 0.25, 400.75);
  ASSERT_TRUE(s.gate_to_gate.has_value());
  EXPECT_NEAR(*s.gate_start_time, 10.025, 1e-9);
  EXPECT_NEAR(*s.gate_to_gate, 40.05, 1e-9);
}

TEST(AnalyseFlight, UnfinishedRunHasNoGateTime) {
  auto samples = straight_run();
  samples.resize(300);  // stops at x = 199 m
  const FlightSummary s = analyse_flight(samples, {}, limits(), 0.0, 400.0);
  EXPECT_TRUE(s.gate_start_time.has_value());
  EXPECT_FALSE(s.gate_finish_time.has_value());
  EXPECT_FALSE(s.gate_to_gate.has_value());
  EXPECT_FALSE(s.crossed_finish);
}

TEST(AnalyseFlight, WithoutGatesNoGateTimes) {
  const FlightSummary s = analyse_flight(straight_run(), {}, limits(), std::nullopt, std::nullopt);
  EXPECT_FALSE(s.gate_start_time.has_value());
  EXPECT_FALSE(s.gate_finish_time.has_value());
  EXPECT_FALSE(s.gate_to_gate.has_value());
  EXPECT_FALSE(s.crossed_finish);
}

TEST(AnalyseFlight, MaxSpeedIsTheLargestTotalSpeed) {
  auto samples = straight_run();
  samples[200].velocity = Vec3(11, 2, -3);
  samples[400].velocity = Vec3(0, 0, 4);
  const FlightSummary s = analyse_flight(samples, {}, limits(), 0.0, 400.0);
  EXPECT_NEAR(s.max_speed, std::sqrt(121.0 + 4.0 + 9.0), 1e-12);
  EXPECT_NEAR(s.max_vertical_speed, 4.0, 1e-12);
}

TEST(AnalyseFlight, TrackingCountsOnlyWhileFlyingThePlan) {
  const std::vector<StatusSample> st = {
      status(0.0, control_status_t::HOLD, Vec3(100, 0, 0), Vec3(5, 0, 0), Vec3(9, 0, 0)),
      status(0.1, control_status_t::WAYPOINT, Vec3(3, 0, 0), Vec3(0.3, 0, 0), Vec3(1, 0, 0)),
      status(0.2, control_status_t::TRAJECTORY, Vec3(0, 4, 0), Vec3(0, 0.4, 0), Vec3(0, 2, 0)),
      status(0.3, control_status_t::NAV_STALE, Vec3(70, 0, 0), Vec3(7, 0, 0), Vec3(8, 0, 0)),
      status(0.4, control_status_t::DONE, Vec3(0, 0, 50), Vec3(6, 0, 0), Vec3(7, 0, 0)),
  };
  const FlightSummary s = analyse_flight(straight_run(), st, limits(), 0.0, 400.0);
  EXPECT_NEAR(s.tracking_max, 4.0, 1e-12);
  EXPECT_NEAR(s.tracking_rms, std::sqrt((9.0 + 16.0) / 2.0), 1e-12);
  EXPECT_NEAR(s.max_commanded_accel, 0.4, 1e-12);
  EXPECT_NEAR(s.max_commanded_accel_fraction, 0.8, 1e-12);
  EXPECT_NEAR(s.max_pseudo_control, 2.0, 1e-12);
  EXPECT_TRUE(s.reached_last_waypoint);
}

TEST(AnalyseFlight, NoPlanFlownMeansNoTrackingFigures) {
  const std::vector<StatusSample> st = {
      status(0.0, control_status_t::HOLD, Vec3(100, 0, 0)),
      status(0.1, control_status_t::NAV_STALE, Vec3(10, 0, 0)),
  };
  const FlightSummary s = analyse_flight(straight_run(), st, limits(), 0.0, 400.0);
  EXPECT_EQ(s.tracking_rms, 0.0);
  EXPECT_EQ(s.tracking_max, 0.0);
  EXPECT_FALSE(s.reached_last_waypoint);
}

TEST(AnalyseFlight, EmptyInputGivesAnEmptySummary) {
  const FlightSummary s = analyse_flight({}, {}, limits(), 0.0, 400.0);
  EXPECT_EQ(s.duration, 0.0);
  EXPECT_EQ(s.max_speed, 0.0);
  EXPECT_FALSE(s.gate_to_gate.has_value());
  EXPECT_FALSE(s.crossed_finish);
}

// ---------------------------------------------------------------------------
// The benchmark rule (judge_flight): each limit fails only beyond 2 %, the
// clearance below 0.8 R_s, and every broken rule is named.

Limits judged_limits() {
  Limits l = limits();
  l.clearance = 6.096;  // R_s 20 ft
  return l;
}

/// The controller's pseudo-control bound (config/controller.yaml).
PseudoControlBound bound() {
  return {5.0, 3.0};
}

/// A flight inside every limit that crossed the finish gate and reached
/// the last waypoint.
FlightSummary clean_flight() {
  FlightSummary s;
  s.crossed_finish = true;
  s.reached_last_waypoint = true;
  s.max_speed = 12.0;
  s.max_vertical_speed = 2.0;
  s.max_commanded_accel_fraction = 1.0;
  s.max_pseudo_control_horizontal = 5.0;
  s.max_pseudo_control_vertical = 3.0;
  s.max_ref_position_jump = kMaxReferenceJump;
  s.min_forward_speed = 0.0;
  s.final_max_speed = 0.0;
  return s;
}

bool names(const Verdict& v, const std::string& text) {
  for (const auto& line : v.failures)
    if (line.find(text) != std::string::npos) return true;
  return false;
}

TEST(JudgeFlight, AFlightAtTheLimitsSucceeds) {
  const Verdict v = judge_flight(clean_flight(), judged_limits(), bound(), 0.8 * 6.096, true);
  EXPECT_TRUE(v.success);
  EXPECT_EQ(v.outcome, Outcome::kSuccess);
  EXPECT_TRUE(v.failures.empty());
  // No obstacles and no gates: the last waypoint is the goal.
  FlightSummary no_gate = clean_flight();
  no_gate.crossed_finish = false;
  EXPECT_TRUE(judge_flight(no_gate, judged_limits(), bound(), std::nullopt, false).success);
  no_gate.reached_last_waypoint = false;
  no_gate.final_max_speed = 1.0;
  const Verdict short_of_it = judge_flight(no_gate, judged_limits(), bound(), std::nullopt, false);
  EXPECT_EQ(short_of_it.outcome, Outcome::kFailure);
  EXPECT_TRUE(names(short_of_it, "did not reach the last waypoint"));
}

TEST(JudgeFlight, EachRuleFailsJustBeyondItsToleranceAndIsNamed) {
  const Limits l = judged_limits();
  struct Case {
    std::string name;
    void (*spoil)(FlightSummary&, const Limits&, bool beyond);
    std::string named;
  };
  const std::vector<Case> cases = {
      {"speed",
       [](FlightSummary& s, const Limits& lim, bool beyond) {
         s.max_speed = lim.max_speed * (beyond ? 1.021 : 1.019);
       },
       "speed (m/s) over"},
      {"vertical speed",
       [](FlightSummary& s, const Limits& lim, bool beyond) {
         s.max_vertical_speed = lim.max_vertical_speed * (beyond ? 1.021 : 1.019);
       },
       "vertical speed"},
      {"reference acceleration",
       [](FlightSummary& s, const Limits&, bool beyond) {
         s.max_commanded_accel_fraction = beyond ? 1.021 : 1.019;
       },
       "reference acceleration"},
      {"horizontal pseudo-control",
       [](FlightSummary& s, const Limits&, bool beyond) {
         s.max_pseudo_control_horizontal = bound().horizontal * (beyond ? 1.021 : 1.019);
       },
       "controller command out of its bound: horizontal"},
      {"vertical pseudo-control",
       [](FlightSummary& s, const Limits&, bool beyond) {
         s.max_pseudo_control_vertical = bound().vertical * (beyond ? 1.021 : 1.019);
       },
       "controller command out of its bound: vertical"},
      {"reference jump",
       [](FlightSummary& s, const Limits&, bool beyond) {
         s.max_ref_position_jump = kMaxReferenceJump * (beyond ? 1.01 : 0.99);
         s.max_ref_position_jump_t = 12.0;
       },
       "reference jump"},
      {"backwards",
       [](FlightSummary& s, const Limits& lim, bool beyond) {
         s.min_forward_speed = -lim.max_speed * (beyond ? 0.021 : 0.019);
       },
       "forward speed"},
  };
  for (const Case& c : cases) {
    FlightSummary inside = clean_flight();
    c.spoil(inside, l, false);
    EXPECT_TRUE(judge_flight(inside, l, bound(), 10.0, true).success) << c.name;
    FlightSummary beyond = clean_flight();
    c.spoil(beyond, l, true);
    const Verdict v = judge_flight(beyond, l, bound(), 10.0, true);
    EXPECT_FALSE(v.success) << c.name;
    ASSERT_EQ(v.failures.size(), 1u) << c.name;
    EXPECT_TRUE(names(v, c.named)) << c.name << ": " << v.failures.front();
  }
}

TEST(JudgeFlight, ClearanceBelowEightTenthsOfRsAndAMissedGateFail) {
  const Limits l = judged_limits();
  // Inside R_s but not below 0.8 R_s: allowed.
  EXPECT_TRUE(judge_flight(clean_flight(), l, bound(), 0.81 * l.clearance, true).success);
  const Verdict close = judge_flight(clean_flight(), l, bound(), 0.79 * l.clearance, true);
  EXPECT_FALSE(close.success);
  EXPECT_TRUE(names(close, "clearance"));

  FlightSummary short_run = clean_flight();
  short_run.crossed_finish = false;
  short_run.max_speed = 2.0 * l.max_speed;
  const Verdict v = judge_flight(short_run, l, bound(), 0.5 * l.clearance, true);
  EXPECT_FALSE(v.success);
  // Every broken rule is reported, not only the first.
  EXPECT_EQ(v.failures.size(), 3u);
  EXPECT_TRUE(names(v, "missed the finish gate"));
  EXPECT_TRUE(names(v, "clearance"));
  EXPECT_TRUE(names(v, "speed (m/s) over"));
}

// ---------------------------------------------------------------------------
// Three outcomes: success, safe stop (short of the goal, nothing broken,
// hovering at the end), failure.

TEST(JudgeFlight, OutcomeWordsAreTheReportsWords) {
  EXPECT_STREQ(to_string(Outcome::kSuccess), "success");
  EXPECT_STREQ(to_string(Outcome::kSafeStop), "safe_stop");
  EXPECT_STREQ(to_string(Outcome::kFailure), "failure");
}

TEST(JudgeFlight, AHoverShortOfTheGoalWithNothingBrokenIsASafeStop) {
  const Limits l = judged_limits();
  FlightSummary stopped = clean_flight();
  stopped.crossed_finish = false;
  stopped.reached_last_waypoint = false;
  stopped.final_max_speed = 0.9 * kHoverSpeed;
  const Verdict v = judge_flight(stopped, l, bound(), l.clearance, true);
  EXPECT_EQ(v.outcome, Outcome::kSafeStop);
  EXPECT_FALSE(v.success);
  EXPECT_TRUE(v.failures.empty());
}

TEST(JudgeFlight, ShortOfTheGoalAndStillMovingIsAFailure) {
  const Limits l = judged_limits();
  FlightSummary drifting = clean_flight();
  drifting.crossed_finish = false;
  drifting.reached_last_waypoint = false;
  drifting.final_max_speed = 1.1 * kHoverSpeed;
  const Verdict v = judge_flight(drifting, l, bound(), l.clearance, true);
  EXPECT_EQ(v.outcome, Outcome::kFailure);
  EXPECT_FALSE(v.success);
  ASSERT_EQ(v.failures.size(), 1u);
  EXPECT_TRUE(names(v, "missed the finish gate and did not end at a hover")) << v.failures[0];
  // Too little data to tell a hover is not a hover.
  drifting.final_max_speed.reset();
  EXPECT_EQ(judge_flight(drifting, l, bound(), l.clearance, true).outcome, Outcome::kFailure);
}

TEST(JudgeFlight, AHoverShortOfTheGoalWithARuleBrokenIsAFailure) {
  const Limits l = judged_limits();
  FlightSummary stopped = clean_flight();
  stopped.crossed_finish = false;
  stopped.reached_last_waypoint = false;
  stopped.final_max_speed = 0.0;
  stopped.max_speed = 1.1 * l.max_speed;
  const Verdict v = judge_flight(stopped, l, bound(), l.clearance, true);
  EXPECT_EQ(v.outcome, Outcome::kFailure);
  EXPECT_TRUE(names(v, "speed"));
  EXPECT_TRUE(names(v, "missed the finish gate"));
  // The goal reached with a rule broken is no success either.
  FlightSummary fast = clean_flight();
  fast.max_speed = 1.1 * l.max_speed;
  EXPECT_EQ(judge_flight(fast, l, bound(), l.clearance, true).outcome, Outcome::kFailure);
}

TEST(JudgeFlight, FailureLinesUseTheDisplayUnit) {
  const Limits l = judged_limits();  // R_s 6.096 m = 20 ft
  const Verdict v =
      judge_flight(clean_flight(), l, bound(), 0.5 * l.clearance, true, DisplayUnit{"ft", 0.3048});
  ASSERT_EQ(v.failures.size(), 1u);
  EXPECT_EQ(v.failures[0], "clearance (ft) below 0.8 R_s: 10 against 16");
}

TEST(AnalyseFlight, FinalSpeedIsTheLargestOverTheLastTwoSeconds) {
  // 10 m/s, then a hover over the last 2 s (10 Hz samples).
  std::vector<NavSample> samples;
  for (int i = 0; i <= 100; ++i)
    samples.push_back(nav(0.1 * i, 1.0 * i, i < 80 ? Vec3(10, 0, 0) : Vec3(0.1, 0, -0.05)));
  FlightSummary s = analyse_flight(samples, {}, limits(), std::nullopt, std::nullopt);
  ASSERT_TRUE(s.final_max_speed.has_value());
  EXPECT_NEAR(*s.final_max_speed, std::hypot(0.1, 0.05), 1e-12);
  // One fast sample inside the window counts.
  samples[81].velocity = Vec3(0, 0.5, 0);
  s = analyse_flight(samples, {}, limits(), std::nullopt, std::nullopt);
  EXPECT_NEAR(*s.final_max_speed, 0.5, 1e-12);
  // Shorter than the window: no figure.
  samples.resize(15);
  EXPECT_FALSE(analyse_flight(samples, {}, limits(), std::nullopt, std::nullopt)
                   .final_max_speed.has_value());
}

// ---------------------------------------------------------------------------
// The ground is a surface like any obstacle.

/// Level at 30 m altitude for 10 s, then down at 2 m/s into the ground at
/// altitude 0 and sitting there (10 Hz samples).
std::vector<NavSample> descent_into_the_ground() {
  std::vector<NavSample> out;
  for (int i = 0; i <= 300; ++i) {
    const double t = 0.1 * i;
    const double altitude = t < 10 ? 30.0 : std::max(30.0 - 2.0 * (t - 10), 0.0);
    NavSample n = nav(t, 5.0 * t, Vec3(5, 0, altitude > 0 && t >= 10 ? 2.0 : 0.0));
    n.position.z() = -altitude;
    out.push_back(n);
  }
  return out;
}

TEST(LeastClearance, CountsTheGround) {
  const auto samples = descent_into_the_ground();
  const world::World flat({}, 0.0);
  const auto c = least_clearance(samples, flat);
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->distance, 0.0, 1e-12);
  EXPECT_TRUE(c->to_ground);
  EXPECT_NEAR(c->t, 25.0, 1e-9);  // the first sample on the ground
  // The same flight over ground 10 m lower keeps 10 m.
  const auto lower = least_clearance(samples, world::World({}, -10.0));
  ASSERT_TRUE(lower.has_value());
  EXPECT_NEAR(lower->distance, 10.0, 1e-9);
  EXPECT_FALSE(least_clearance({}, flat).has_value());
}

TEST(LeastClearance, TheNearerSurfaceCounts) {
  // Level at 30 m; a box 20 m high whose top passes 10 m below the path.
  const std::vector<NavSample> samples = {nav(0, 0), nav(1, 10), nav(2, 20)};
  ObstacleSpec box;
  box.id = 1;
  box.kind = ObstacleSpec::Kind::kBox;
  box.north = 10;
  box.east = 0;
  box.length = 4;
  box.width = 4;
  box.height = 20;
  const auto c = least_clearance(samples, world::World({box}, 0.0));
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->distance, 10.0, 1e-9);
  EXPECT_FALSE(c->to_ground);
  EXPECT_NEAR(c->t, 1.0, 1e-12);
}

TEST(JudgeFlight, AFlightIntoTheGroundFails) {
  const Limits l = judged_limits();
  const auto samples = descent_into_the_ground();
  const FlightSummary s = analyse_flight(samples, {}, l, std::nullopt, std::nullopt);
  const auto c = least_clearance(samples, world::World({}, 0.0));
  ASSERT_TRUE(c.has_value());
  const Verdict v = judge_flight(s, l, bound(), c->distance, false);
  EXPECT_EQ(v.outcome, Outcome::kFailure);
  EXPECT_TRUE(names(v, "clearance"));
}

// ---------------------------------------------------------------------------
// The controller's command against its bound, and the reference's
// continuity, from CONTROL_STATUS samples.

/// A plan flown at 50 Hz for 4 s: the reference moves north at 3 m/s.
std::vector<StatusSample> plan_at_three_metres_per_second() {
  std::vector<StatusSample> out;
  for (int i = 0; i <= 200; ++i) {
    StatusSample st = status(0.02 * i, control_status_t::WAYPOINT, Vec3(0.1, 0, 0), Vec3::Zero(),
                             Vec3(0.5, 0, -0.2));
    st.ref_position = Vec3(3.0 * st.t, 0, -30);
    st.ref_velocity = Vec3(3, 0, 0);
    out.push_back(st);
  }
  return out;
}

FlightSummary analysed(const std::vector<StatusSample>& st) {
  return analyse_flight(straight_run(), st, limits(), 0.0, 400.0);
}

Verdict judged(const FlightSummary& s) {
  return judge_flight(s, judged_limits(), bound(), 10.0, true);
}

TEST(AnalyseFlight, ASmoothPlanHasNoReferenceJumpAndPasses) {
  const FlightSummary s = analysed(plan_at_three_metres_per_second());
  EXPECT_NEAR(s.max_ref_position_jump, 0.0, 1e-9);
  EXPECT_NEAR(s.max_ref_velocity_jump, 0.0, 1e-9);
  EXPECT_NEAR(s.max_pseudo_control_horizontal, 0.5, 1e-12);
  EXPECT_NEAR(s.max_pseudo_control_vertical, 0.2, 1e-12);
  const Verdict v = judged(s);
  EXPECT_EQ(v.outcome, Outcome::kSuccess) << (v.failures.empty() ? "" : v.failures[0]);
}

TEST(AnalyseFlight, AMissingSampleIsNoJump) {
  auto st = plan_at_three_metres_per_second();
  st.erase(st.begin() + 50, st.begin() + 100);  // a second without status
  EXPECT_NEAR(analysed(st).max_ref_position_jump, 0.0, 1e-9);
}

// The reference 5 m off the vehicle (a lapsed reference, an old plan)
// steps onto it: the controller took over from the vehicle's state, and
// nothing is chased. Counted, not failed.
TEST(JudgeFlight, AStepOntoTheVehicleIsAResyncNotAJump) {
  auto st = plan_at_three_metres_per_second();
  for (size_t i = 0; i < 120; ++i) {
    st[i].ref_position.y() += 5.0;
    st[i].position_error.y() += 5.0;
  }
  const FlightSummary s = analysed(st);
  EXPECT_EQ(s.reference_resyncs, 1);
  EXPECT_NEAR(s.max_ref_position_jump, 0.0, 1e-9);
  const Verdict v = judged(s);
  EXPECT_EQ(v.outcome, Outcome::kSuccess) << (v.failures.empty() ? "" : v.failures[0]);
  // The same step that leaves the vehicle 5 m off its reference fails.
  auto away = plan_at_three_metres_per_second();
  for (size_t i = 120; i < away.size(); ++i) {
    away[i].ref_position.y() += 5.0;
    away[i].position_error.y() += 5.0;
  }
  const FlightSummary a = analysed(away);
  EXPECT_EQ(a.reference_resyncs, 0);
  EXPECT_NEAR(a.max_ref_position_jump, 5.0, 1e-9);
  EXPECT_EQ(judged(a).outcome, Outcome::kFailure);
}

TEST(JudgeFlight, AReferenceJumpFails) {
  auto st = plan_at_three_metres_per_second();
  // From sample 120 on the reference is 1.5 m further east: a step, the
  // vehicle 1.5 m off it.
  for (size_t i = 120; i < st.size(); ++i) {
    st[i].ref_position.y() += 1.5;
    st[i].position_error.y() += 1.5;
  }
  const FlightSummary s = analysed(st);
  EXPECT_NEAR(s.max_ref_position_jump, 1.5, 1e-9);
  ASSERT_TRUE(s.max_ref_position_jump_t.has_value());
  EXPECT_NEAR(*s.max_ref_position_jump_t, 2.4, 1e-12);
  const Verdict v = judged(s);
  EXPECT_EQ(v.outcome, Outcome::kFailure);
  EXPECT_TRUE(names(v, "reference jump"));
  EXPECT_EQ(s.reference_resyncs, 0);
  // A step of the velocity is measured too (its limit is the acceleration).
  st = plan_at_three_metres_per_second();
  for (size_t i = 120; i < st.size(); ++i) st[i].ref_velocity.x() += 2.0;
  EXPECT_NEAR(analysed(st).max_ref_velocity_jump, 2.0, 1e-9);
}

TEST(JudgeFlight, APseudoControlOverItsBoundFails) {
  auto st = plan_at_three_metres_per_second();
  st[150].commanded_accel = Vec3(4.0, 3.2, 0.0);  // 5.12 horizontal, bound 5 + 2 %
  FlightSummary s = analysed(st);
  EXPECT_NEAR(s.max_pseudo_control_horizontal, std::hypot(4.0, 3.2), 1e-12);
  Verdict v = judged(s);
  EXPECT_EQ(v.outcome, Outcome::kFailure);
  EXPECT_TRUE(names(v, "controller command out of its bound: horizontal"));

  st = plan_at_three_metres_per_second();
  st[150].commanded_accel = Vec3(0.0, 0.0, -3.1);  // up, bound 3 + 2 %
  s = analysed(st);
  EXPECT_NEAR(s.max_pseudo_control_vertical, 3.1, 1e-12);
  v = judged(s);
  EXPECT_EQ(v.outcome, Outcome::kFailure);
  EXPECT_TRUE(names(v, "controller command out of its bound: vertical"));
}

TEST(AnalyseFlight, SamplesBeforeEngagementAreIgnored) {
  // A hold somewhere else with a large command, then the plan: the step
  // from the hold's reference to the plan's and the hold's command are not
  // the plan's.
  std::vector<StatusSample> st;
  for (int i = 0; i < 50; ++i) {
    StatusSample hold = status(-1.0 + 0.02 * i, control_status_t::HOLD, Vec3(5, 0, 0),
                               Vec3(3, 0, 0), Vec3(9, 0, 7));
    hold.ref_position = Vec3(-200, 40, -60);
    hold.ref_velocity = Vec3::Zero();
    st.push_back(hold);
  }
  const auto plan = plan_at_three_metres_per_second();
  st.insert(st.end(), plan.begin(), plan.end());
  const FlightSummary s = analysed(st);
  EXPECT_NEAR(s.max_ref_position_jump, 0.0, 1e-9);
  EXPECT_NEAR(s.max_pseudo_control_horizontal, 0.5, 1e-12);
  EXPECT_NEAR(s.max_pseudo_control_vertical, 0.2, 1e-12);
  EXPECT_NEAR(s.max_commanded_accel, 0.0, 1e-12);
  EXPECT_NEAR(s.tracking_max, 0.1, 1e-12);
  const Verdict v = judged(s);
  EXPECT_EQ(v.outcome, Outcome::kSuccess) << (v.failures.empty() ? "" : v.failures[0]);
  // The same hold samples flown as a plan would fail on both counts (the
  // vehicle still where it flew the hold when the plan's reference starts).
  for (int i = 0; i < 50; ++i) st[i].mode = control_status_t::WAYPOINT;
  st[50].position_error = st[50].ref_position - (st[49].ref_position - st[49].position_error);
  const Verdict engaged = judged(analysed(st));
  EXPECT_TRUE(names(engaged, "reference jump"));
  EXPECT_TRUE(names(engaged, "controller command out of its bound"));
}

TEST(AnalyseFlight, AModeAddedLaterToFlyAPlanIsJudged) {
  EXPECT_TRUE(flies_a_plan(control_status_t::WAYPOINT));
  EXPECT_TRUE(flies_a_plan(control_status_t::TRAJECTORY));
  EXPECT_FALSE(flies_a_plan(control_status_t::HOLD));
  EXPECT_FALSE(flies_a_plan(control_status_t::NAV_STALE));
  EXPECT_FALSE(flies_a_plan(control_status_t::DONE));
  constexpr int kUnknownMode = 42;
  EXPECT_TRUE(flies_a_plan(kUnknownMode));
}

TEST(ScanToPlan, FromEachScanToTheFirstStepOnAMapHoldingIt) {
  // Steps at 10 Hz from t = 1.0 to 2.0 s, each on the newest map built by
  // then at 5 Hz (built 0.02 s after the scan it holds); scans at 12.5 Hz.
  std::vector<PlanStep> steps;
  for (int i = 0; i <= 10; ++i) {  // in ms, exact
    const int t = 1000 + 100 * i;
    const int built = (t - 20) / 200 * 200;  // the last field build
    const int newest_scan = built / 80 * 80;
    steps.push_back({t / 1000.0, newest_scan / 1000.0});
  }
  std::vector<double> scans;
  for (int k = 0; k <= 30; ++k) scans.push_back(80 * k / 1000.0);
  const std::vector<double> latencies = scan_to_plan_latencies(scans, steps);
  // Scans before planning began are not counted, nor those after it ended
  // (no step planned on them).
  ASSERT_FALSE(latencies.empty());
  for (double l : latencies) {
    EXPECT_GE(l, 0.0);
    EXPECT_LE(l, 0.2 + 0.1 + 0.08 + 1e-9);  // a field period, a step period, a scan period
  }
  // By hand: the scan at 1.04 s is in the map built at 1.2 s (newest scan
  // 1.12 s), planned on first by the step at 1.3 s.
  const std::vector<double> one = scan_to_plan_latencies({1.04}, steps);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_NEAR(one[0], 1.3 - 1.04, 1e-9);

  // A pause in planning: a scan before it is answered by no step after it.
  std::vector<PlanStep> paused = {{1.0, 0.96}, {1.1, 0.96}, {5.0, 4.96}};
  EXPECT_TRUE(scan_to_plan_latencies({1.05}, paused).empty());
  EXPECT_TRUE(scan_to_plan_latencies({0.5}, paused).empty());  // before planning
  EXPECT_TRUE(scan_to_plan_latencies({}, paused).empty());
}

}  // namespace
}  // namespace ofn::report
