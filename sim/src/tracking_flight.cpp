#include "ofn/sim/tracking_flight.hpp"

#include <algorithm>
#include <cmath>

#include "ofn/vehicle_sim/disturbances.hpp"

namespace ofn::sim {
namespace {

using control::ControlOutput;
using control::facing_along;
using control::GuidanceReference;
using control::kMinLegHorizontal;
using control::make_adaptive_element;
using control::PathHeadingFilter;
using control::predict_estimate;
using control::Reference;
using control::SweepCoverage;
using control::TrajectoryController;
using control::VehicleEstimate;
using control::WaypointGuidance;
using control::YawSweepGenerator;

bool within(const vehicle::Controls& c, const vehicle::RotorcraftParams& p) {
  const auto v = c.as_array(), lo = p.min_controls.as_array(), hi = p.max_controls.as_array();
  for (int i = 0; i < 4; ++i)
    if (!std::isfinite(v[i]) || v[i] < lo[i] || v[i] > hi[i]) return false;
  return true;
}

}  // namespace

TrackingResult fly_tracking(const Scenario& scenario, const TrackingSetup& setup,
                            const TrackingFlightConfig& config) {
  const vehicle::RotorcraftParams airframe =
      vehicle::apply_variation(setup.nominal, scenario.vehicle);
  vehicle::SimulatedVehicle sim(airframe, scenario.wind, scenario.disturbances,
                                scenario.ground_altitude);
  const auto trim =
      vehicle::trim(sim.model(), scenario.start_velocity, scenario.start_heading, scenario.wind);
  vehicle::RotorcraftState start = trim.state;
  start.position = scenario.start_position;
  sim.reset(start, 0.0);
  sim.set_command(trim.controls);

  TrajectoryController controller(setup.nominal, setup.gains,
                                  make_adaptive_element(setup.adaptive));
  WaypointGuidance guidance(setup.guidance);
  std::vector<Waypoint> route = scenario.waypoints;
  guidance.set_mission(route, scenario.cruise_speed, scenario.limits, start.position,
                       start.velocity);

  const double dt = 1.0 / config.control_rate;
  const int physics_per_control =
      std::max(1, static_cast<int>(std::lround(config.physics_rate / config.control_rate)));
  const int steps = static_cast<int>(std::lround(config.duration / dt));
  const int trace_every = std::max(1, static_cast<int>(std::lround(config.trace_interval / dt)));

  TrackingResult r;
  PathHeadingFilter path_heading(setup.heading);
  path_heading.reset(scenario.start_heading);
  YawSweepGenerator sweep(setup.sweep);
  double sum_sq = 0, sum_sq_first = 0, sum_sq_second = 0;
  int n = 0, n_first = 0, n_second = 0;
  const double half_time = 0.5 * (config.duration + config.settle_time);
  for (int k = 0; k < steps; ++k) {
    const double t = k * dt;
    const vehicle::NavSample nav = sim.measure();
    GuidanceReference g = guidance.update(nav.position, nav.velocity, dt);
    if (g.done && config.round_trip) {
      std::reverse(route.begin(), route.end());
      guidance.set_mission(route, scenario.cruise_speed, scenario.limits, nav.position,
                           nav.velocity);
      g = guidance.update(nav.position, nav.velocity, dt);
      ++r.legs_flown;
    }
    Reference ref;
    ref.position = g.position;
    ref.velocity = g.velocity;
    ref.acceleration = g.acceleration;
    // As the service: face the leg (not a vertical one), sweep on top.
    ref.yaw = path_heading.update(facing_along(g.leg_direction, kMinLegHorizontal), dt);
    ref.yaw_rate = path_heading.turn_rate();
    if (config.yaw_sweep && setup.sweep.enabled) {
      const SweepCoverage coverage{scenario.limits.clearance,
                                   setup.stop_accel_fraction * scenario.limits.max_accel};
      double sweep_rate = 0;
      ref.yaw = wrap_angle(
          ref.yaw + sweep.update_at_speed(std::hypot(nav.velocity.x(), nav.velocity.y()),
                                          setup.heading.min_speed, coverage, dt, &sweep_rate));
      ref.yaw_rate += sweep_rate;
    }

    VehicleEstimate x;
    x.position = nav.position;
    x.velocity = nav.velocity;
    x.attitude = nav.attitude;
    x.body_rates = nav.body_rates;
    // As the service: carried forward from its time of validity to now.
    x = predict_estimate(x, nav.acceleration, sim.time() - nav.time, setup.nav_prediction);
    const ControlOutput out = controller.step(ref, x, dt);
    r.all_valid = r.all_valid && out.valid;
    r.all_within_limits = r.all_within_limits && within(out.controls, setup.nominal);
    sim.set_command(out.controls);
    for (int i = 0; i < physics_per_control; ++i) sim.step(dt / physics_per_control);

    const auto& s = sim.model().state();
    if (!s.position.allFinite() || !s.velocity.allFinite()) {
      r.finite = false;
      break;
    }
    const double error = (ref.position - s.position).norm();
    const double weights = controller.adaptive().weight_norm();
    r.max_weight_norm = std::max(r.max_weight_norm, weights);
    r.final_weight_norm = weights;
    if (k % trace_every == 0) {
      r.weight_norm_trace.push_back(weights);
      r.error_trace.push_back(error);
    }
    if (t >= config.settle_time) {
      sum_sq += error * error;
      ++n;
      r.max_error = std::max(r.max_error, error);
      if (t < half_time) {
        sum_sq_first += error * error;
        ++n_first;
      } else {
        sum_sq_second += error * error;
        ++n_second;
      }
    }
  }
  r.rms_error = n > 0 ? std::sqrt(sum_sq / n) : 0.0;
  r.rms_error_first_half = n_first > 0 ? std::sqrt(sum_sq_first / n_first) : 0.0;
  r.rms_error_second_half = n_second > 0 ? std::sqrt(sum_sq_second / n_second) : 0.0;
  return r;
}

}  // namespace ofn::sim
