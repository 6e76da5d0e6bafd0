// Flight figures of merit: gate timing, speeds and tracking error.

#include <gtest/gtest.h>

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

/// A flight inside every limit that crossed the finish gate.
FlightSummary clean_flight() {
  FlightSummary s;
  s.crossed_finish = true;
  s.max_speed = 12.0;
  s.max_vertical_speed = 2.0;
  s.max_commanded_accel_fraction = 1.0;
  s.min_forward_speed = 0.0;
  return s;
}

bool names(const Verdict& v, const std::string& text) {
  for (const auto& line : v.failures)
    if (line.find(text) != std::string::npos) return true;
  return false;
}

TEST(JudgeFlight, AFlightAtTheLimitsSucceeds) {
  const Verdict v = judge_flight(clean_flight(), judged_limits(), 0.8 * 6.096, true);
  EXPECT_TRUE(v.success);
  EXPECT_TRUE(v.failures.empty());
  // No obstacles and no gates: limits alone.
  FlightSummary no_gate = clean_flight();
  no_gate.crossed_finish = false;
  EXPECT_TRUE(judge_flight(no_gate, judged_limits(), std::nullopt, false).success);
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
      {"commanded acceleration",
       [](FlightSummary& s, const Limits&, bool beyond) {
         s.max_commanded_accel_fraction = beyond ? 1.021 : 1.019;
       },
       "commanded acceleration"},
      {"backwards",
       [](FlightSummary& s, const Limits& lim, bool beyond) {
         s.min_forward_speed = -lim.max_speed * (beyond ? 0.021 : 0.019);
       },
       "forward speed"},
  };
  for (const Case& c : cases) {
    FlightSummary inside = clean_flight();
    c.spoil(inside, l, false);
    EXPECT_TRUE(judge_flight(inside, l, 10.0, true).success) << c.name;
    FlightSummary beyond = clean_flight();
    c.spoil(beyond, l, true);
    const Verdict v = judge_flight(beyond, l, 10.0, true);
    EXPECT_FALSE(v.success) << c.name;
    ASSERT_EQ(v.failures.size(), 1u) << c.name;
    EXPECT_TRUE(names(v, c.named)) << c.name << ": " << v.failures.front();
  }
}

TEST(JudgeFlight, ClearanceBelowEightTenthsOfRsAndAMissedGateFail) {
  const Limits l = judged_limits();
  // Inside R_s but not below 0.8 R_s: allowed.
  EXPECT_TRUE(judge_flight(clean_flight(), l, 0.81 * l.clearance, true).success);
  const Verdict close = judge_flight(clean_flight(), l, 0.79 * l.clearance, true);
  EXPECT_FALSE(close.success);
  EXPECT_TRUE(names(close, "clearance"));

  FlightSummary short_run = clean_flight();
  short_run.crossed_finish = false;
  short_run.max_speed = 2.0 * l.max_speed;
  const Verdict v = judge_flight(short_run, l, 0.5 * l.clearance, true);
  EXPECT_FALSE(v.success);
  // Every broken rule is reported, not only the first.
  EXPECT_EQ(v.failures.size(), 3u);
  EXPECT_TRUE(names(v, "missed the finish gate"));
  EXPECT_TRUE(names(v, "clearance"));
  EXPECT_TRUE(names(v, "speed (m/s) over"));
}

}  // namespace
}  // namespace ofn::report
