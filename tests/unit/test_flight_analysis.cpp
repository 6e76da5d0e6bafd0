// Flight figures of merit: gate timing, speeds and tracking error.

#include <gtest/gtest.h>

#include <cmath>
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

}  // namespace
}  // namespace ofn::report
