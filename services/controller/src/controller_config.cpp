#include "ofn/controller/controller_config.hpp"

#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace ofn::control {
namespace {

// Gains per axis: three numbers, none negative (or each in [lo, hi]).
Vec3 read_vec3(YamlReader& r, const std::string& key, const Vec3& fallback, double lo = 0.0,
               double hi = std::numeric_limits<double>::infinity()) {
  const auto v = r.numbers_in(key, {fallback.x(), fallback.y(), fallback.z()}, lo, hi);
  return Vec3(v[0], v[1], v[2]);
}
// Per channel: collective, longitudinal cyclic, lateral cyclic, pedal.
vehicle::Controls read_controls(YamlReader& r, const std::string& key,
                                const vehicle::Controls& fallback, double lo, double hi) {
  const auto a = fallback.as_array();
  const auto v = r.numbers_in(key, {a[0], a[1], a[2], a[3]}, lo, hi);
  return vehicle::Controls::from_array({v[0], v[1], v[2], v[3]});
}

// Every parameter of the model is read below; a new one must be too, or
// the controller would silently keep the simulator's value of it.
static_assert(sizeof(vehicle::RotorcraftParams) == 35 * sizeof(double),
              "a new RotorcraftParams field needs its nominal_airframe setting");

// The controller's estimate of the airframe, the model it inverts. The
// defaults are the simulator's airframe. Lower bounds keep every quantity
// the inversion divides by away from zero.
vehicle::RotorcraftParams read_nominal_airframe(YamlReader& r, vehicle::RotorcraftParams p) {
  p.mass = r.number_in("mass", p.mass, 1.0, 1e4);
  p.inertia = read_vec3(r, "inertia", p.inertia, 1e-3, 1e5);
  p.air_density = r.number_in("air_density", p.air_density, 0.1, 2.0);
  p.rotor_radius = r.number_in("rotor_radius", p.rotor_radius, 0.05, 20.0);
  p.rotor_speed = r.number_in("rotor_speed", p.rotor_speed, 1.0, 5000.0);
  p.lift_slope = r.number_in("lift_slope", p.lift_slope, 0.1, 10.0);
  p.solidity = r.number_in("solidity", p.solidity, 0.001, 1.0);
  p.profile_drag = r.number_in("profile_drag", p.profile_drag, 0.0, 0.1);
  p.inflow_time_constant = r.number_in("inflow_time_constant", p.inflow_time_constant, 0.01, 2.0);
  p.hub_height = r.number_in("hub_height", p.hub_height, 0.01, 10.0);
  p.flap_stiffness = r.number_in("flap_stiffness", p.flap_stiffness, 0.0, 1e6);
  p.flap_time_constant = r.number_in("flap_time_constant", p.flap_time_constant, 0.01, 2.0);
  p.cyclic_to_flap = r.number_in("cyclic_to_flap", p.cyclic_to_flap, 0.05, 5.0);
  p.flap_blowback = r.number_in("flap_blowback", p.flap_blowback, 0.0, 1.0);
  p.tail_arm = r.number_in("tail_arm", p.tail_arm, 0.05, 20.0);
  p.tail_thrust_per_rad = r.number_in("tail_thrust_per_rad", p.tail_thrust_per_rad, 1.0, 1e6);
  p.tail_velocity_damping = r.number_in("tail_velocity_damping", p.tail_velocity_damping, 0.0, 1e4);
  p.drag_area = read_vec3(r, "drag_area", p.drag_area, 0.0, 100.0);
  p.min_controls = read_controls(r, "min_controls", p.min_controls, -1.5, 1.5);
  p.max_controls = read_controls(r, "max_controls", p.max_controls, -1.5, 1.5);
  const auto lo = p.min_controls.as_array(), hi = p.max_controls.as_array();
  for (int i = 0; i < 4; ++i)
    if (!(lo[i] < hi[i]))
      r.fail("max_controls", "expected every limit above its min_controls counterpart");
  p.actuator_rate = read_controls(r, "actuator_rate", p.actuator_rate, 0.01, 100.0);
  p.servo_time_constant = r.number_in("servo_time_constant", p.servo_time_constant, 0.001, 1.0);
  return p;
}

}  // namespace

ControllerConfig load_controller_config(YamlReader& r) {
  ControllerConfig c;
  c.rate = r.number_in("rate_hz", c.rate, 10.0, 1000.0);
  c.status_rate = r.number_in("status_rate_hz", c.status_rate, 1.0, 1000.0);
  c.nav_timeout = r.number_in("nav_timeout", c.nav_timeout, 0.01, 10.0);
  c.nav_prediction = r.number_in("nav_prediction", c.nav_prediction, 0.0, 1.0);
  c.ref_traj_timeout = r.number_in("ref_traj_timeout", c.ref_traj_timeout, 0.01, 10.0);
  YamlReader selector = r.child("reference_selector");
  c.selector.jump_position =
      selector.number_in("jump_position", c.selector.jump_position, 0.01, 100.0);
  c.selector.jump_velocity =
      selector.number_in("jump_velocity", c.selector.jump_velocity, 0.01, 100.0);
  c.selector.resync_position =
      selector.number_in("resync_position", c.selector.resync_position, 0.01, 100.0);
  c.selector.resync_velocity =
      selector.number_in("resync_velocity", c.selector.resync_velocity, 0.01, 100.0);
  c.selector.stop_accel_fraction =
      selector.number_in("stop_accel_fraction", c.selector.stop_accel_fraction, 0.05, 1.0);
  c.selector.hold_deceleration =
      selector.number_in("hold_deceleration", c.selector.hold_deceleration, 0.01, 20.0);
  c.selector.lapse_time = selector.number_in("lapse_time", c.selector.lapse_time, 0.02, 10.0);
  selector.finish();
  YamlReader perception = r.child("perception_watch");
  c.perception.enabled = perception.boolean("enabled", c.perception.enabled);
  c.perception.max_status_age =
      perception.number_in("max_status_age", c.perception.max_status_age, 0.05, 60.0);
  c.perception.max_map_age =
      perception.number_in("max_map_age", c.perception.max_map_age, 0.05, 60.0);
  perception.finish();
  YamlReader gate = r.child("command_gate");
  c.gate.max_speed = gate.number_in("max_speed", c.gate.max_speed, 0.1, 100.0);
  c.gate.max_vertical_speed =
      gate.number_in("max_vertical_speed", c.gate.max_vertical_speed, 0.1, 100.0);
  c.gate.max_accel = gate.number_in("max_accel", c.gate.max_accel, 0.1, 100.0);
  YamlReader fence = gate.child("geofence");
  const auto north =
      fence.numbers_in("north", {c.gate.fence_min.x(), c.gate.fence_max.x()}, -1e6, 1e6);
  const auto east =
      fence.numbers_in("east", {c.gate.fence_min.y(), c.gate.fence_max.y()}, -1e6, 1e6);
  // Altitude up, as a user reads it; the box is kept in NED.
  const auto altitude =
      fence.numbers_in("altitude", {-c.gate.fence_max.z(), -c.gate.fence_min.z()}, -1e4, 1e5);
  for (const auto& [key, range] :
       {std::pair<const char*, const std::vector<double>*>{"north", &north},
        {"east", &east},
        {"altitude", &altitude}})
    if (!((*range)[0] < (*range)[1])) fence.fail(key, "expected [lowest, highest], lowest first");
  c.gate.fence_min = Vec3(north[0], east[0], -altitude[1]);
  c.gate.fence_max = Vec3(north[1], east[1], -altitude[0]);
  fence.finish();
  gate.finish();
  YamlReader outer = r.child("outer_loop");
  c.gains.position = read_vec3(outer, "position_gain", c.gains.position);
  c.gains.velocity = read_vec3(outer, "velocity_gain", c.gains.velocity);
  c.gains.integral = read_vec3(outer, "integral_gain", c.gains.integral);
  c.gains.integral_limit = outer.number_in("integral_limit", c.gains.integral_limit, 0.0, 20.0);
  c.gains.integral_band = outer.number_in("integral_band", c.gains.integral_band, 0.0, 1000.0);
  c.gains.max_horizontal_accel =
      outer.number_in("max_horizontal_accel", c.gains.max_horizontal_accel, 0.1, 20.0);
  c.gains.max_vertical_accel =
      outer.number_in("max_vertical_accel", c.gains.max_vertical_accel, 0.1, 20.0);
  c.gains.max_tilt = deg2rad(outer.number_in("max_tilt_deg", rad2deg(c.gains.max_tilt), 1.0, 60.0));
  c.gains.governor_over_limit =
      outer.number_in("governor_over_limit", c.gains.governor_over_limit, 1.0, 10.0);
  c.gains.outer_reference_frequency =
      outer.number_in("reference_frequency", c.gains.outer_reference_frequency, 0.05, 20.0);
  c.gains.outer_reference_damping =
      outer.number_in("reference_damping", c.gains.outer_reference_damping, 0.1, 5.0);
  outer.finish();
  YamlReader inner = r.child("inner_loop");
  c.gains.attitude = read_vec3(inner, "attitude_gain", c.gains.attitude);
  c.gains.rate = read_vec3(inner, "rate_gain", c.gains.rate);
  c.gains.attitude_integral = read_vec3(inner, "integral_gain", c.gains.attitude_integral);
  c.gains.attitude_integral_limit =
      inner.number_in("integral_limit", c.gains.attitude_integral_limit, 0.0, 100.0);
  c.gains.inner_reference_frequency =
      inner.number_in("reference_frequency", c.gains.inner_reference_frequency, 0.5, 100.0);
  c.gains.inner_reference_damping =
      inner.number_in("reference_damping", c.gains.inner_reference_damping, 0.1, 5.0);
  inner.finish();
  YamlReader adaptive = r.child("adaptive");
  c.adaptive.enabled = adaptive.boolean("enabled", c.adaptive.enabled);
  c.gains.hedging = adaptive.boolean("hedging", c.gains.hedging);
  const int seed = adaptive.integer("seed", static_cast<int>(c.adaptive.seed));
  if (seed < 0) adaptive.fail("seed", "expected a whole number >= 0");
  c.adaptive.seed = static_cast<uint32_t>(seed);
  for (auto [key, net] : {std::pair<const char*, NetworkSettings*>{"outer", &c.adaptive.outer},
                          std::pair<const char*, NetworkSettings*>{"inner", &c.adaptive.inner}}) {
    YamlReader n = adaptive.child(key);
    net->hidden = n.integer("hidden", net->hidden);
    if (net->hidden < 1 || net->hidden > 64) n.fail("hidden", "expected 1 to 64 neurons");
    net->output_rate = n.number_in("output_rate", net->output_rate, 0.0, 1e4);
    net->hidden_rate = n.number_in("hidden_rate", net->hidden_rate, 0.0, 1e4);
    net->e_modification = n.number_in("e_modification", net->e_modification, 0.0, 100.0);
    net->dead_zone = n.number_in("dead_zone", net->dead_zone, 0.0, 100.0);
    net->max_weight_norm = n.number_in("max_weight_norm", net->max_weight_norm, 0.1, 1e4);
    net->max_output = n.number_in("max_output", net->max_output, 0.0, 1e3);
    n.finish();
  }
  adaptive.finish();
  YamlReader guidance = r.child("guidance");
  c.guidance.accel_fraction =
      guidance.number_in("accel_fraction", c.guidance.accel_fraction, 0.05, 1.0);
  c.guidance.speed_fraction =
      guidance.number_in("speed_fraction", c.guidance.speed_fraction, 0.5, 1.0);
  c.guidance.speed_gain = guidance.number_in("speed_gain", c.guidance.speed_gain, 0.05, 20.0);
  c.guidance.jerk_fraction =
      guidance.number_in("jerk_fraction", c.guidance.jerk_fraction, 0.05, 100.0);
  c.guidance.max_lead = guidance.number_in("max_lead", c.guidance.max_lead, 0.1, 1000.0);
  c.guidance.stop_speed = guidance.number_in("stop_speed", c.guidance.stop_speed, 0.01, 10.0);
  guidance.finish();
  YamlReader reserve = r.child("speed_reserve");
  SpeedReserveSettings& sr = c.speed_reserve;
  sr.enabled = reserve.boolean("enabled", sr.enabled);
  sr.time_constant = reserve.number_in("time_constant", sr.time_constant, 0.1, 600.0);
  sr.onset = reserve.number_in("onset", sr.onset, 0.0, 10.0);
  sr.full = reserve.number_in("full", sr.full, sr.onset, 20.0);
  sr.sigmas = reserve.number_in("sigmas", sr.sigmas, 0.0, 5.0);
  sr.max_fraction = reserve.number_in("max_fraction", sr.max_fraction, 0.0, 0.9);
  reserve.finish();
  YamlReader sweep = r.child("yaw_sweep");
  c.sweep.enabled = sweep.boolean("enabled", c.sweep.enabled);
  c.sweep.frequency = sweep.number_in("frequency_hz", c.sweep.frequency, 0.01, 5.0);
  c.sweep.total_angle =
      deg2rad(sweep.number_in("total_deg", rad2deg(c.sweep.total_angle), 0.0, 180.0));
  c.sweep.scanner_timeout = sweep.number_in("scanner_timeout", c.sweep.scanner_timeout, 0.05, 60.0);
  c.sweep.wide_total_angle =
      deg2rad(sweep.number_in("wide_total_deg", rad2deg(c.sweep.wide_total_angle), 0.0, 180.0));
  c.sweep.widen_rate =
      deg2rad(sweep.number_in("widen_rate_deg_s", rad2deg(c.sweep.widen_rate), 0.1, 180.0));
  c.sweep.cover_clearance = sweep.boolean("cover_clearance", c.sweep.cover_clearance);
  c.sweep.cover_total_angle =
      deg2rad(sweep.number_in("cover_total_deg", rad2deg(c.sweep.cover_total_angle), 1.0, 360.0));
  sweep.finish();
  YamlReader heading = r.child("path_heading");
  c.heading.max_rate =
      deg2rad(heading.number_in("max_rate_deg_s", rad2deg(c.heading.max_rate), 1.0, 360.0));
  c.heading.max_accel =
      deg2rad(heading.number_in("max_accel_deg_s2", rad2deg(c.heading.max_accel), 1.0, 3600.0));
  c.heading.min_speed = heading.number_in("min_speed", c.heading.min_speed, 0.0, 20.0);
  c.heading.look_ahead = heading.number_in("look_ahead", c.heading.look_ahead, 0.0, 20.0);
  heading.finish();
  YamlReader nominal = r.child("nominal_airframe");
  c.nominal = read_nominal_airframe(nominal, c.nominal);
  nominal.finish();
  r.finish();
  return c;
}

}  // namespace ofn::control
