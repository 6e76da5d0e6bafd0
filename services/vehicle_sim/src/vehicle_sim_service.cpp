#include "ofn/vehicle_sim/vehicle_sim_service.hpp"

#include "ofn/common/channels.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/sim_clock_t.hpp"

namespace ofn::vehicle {

VehicleSimConfig load_vehicle_sim_config(YamlReader& r) {
  VehicleSimConfig c;
  c.physics_rate = r.number_in("physics_rate_hz", c.physics_rate, 200.0, 5000.0);
  c.nav_rate = r.number_in("nav_rate_hz", c.nav_rate, 10.0, 1000.0);
  c.command_timeout = r.number_in("command_timeout", c.command_timeout, 0.01, 60.0);
  c.hold_until_engaged = r.boolean("hold_until_engaged", c.hold_until_engaged);
  c.engage_timeout = r.number_in("engage_timeout", c.engage_timeout, 0.0, 3600.0);
  YamlReader airframe = r.child("airframe");
  auto& p = c.params;
  p.mass = airframe.number_in("mass", p.mass, 1.0, 1e4);
  const auto inertia = airframe.numbers("inertia", {p.inertia.x(), p.inertia.y(), p.inertia.z()});
  for (double i : inertia)
    if (i <= 0) airframe.fail("inertia", "every moment of inertia must be > 0");
  p.inertia = Vec3(inertia[0], inertia[1], inertia[2]);
  p.flap_time_constant = airframe.number_in("flap_time_constant", p.flap_time_constant, 0.01, 2.0);
  p.inflow_time_constant =
      airframe.number_in("inflow_time_constant", p.inflow_time_constant, 0.01, 2.0);
  p.servo_time_constant =
      airframe.number_in("servo_time_constant", p.servo_time_constant, 0.001, 1.0);
  p.actuator_rate = airframe.number_in("actuator_rate", p.actuator_rate, 0.01, 100.0);
  airframe.finish();
  r.finish();
  if (c.nav_rate > c.physics_rate) r.fail("nav_rate_hz", "must not exceed physics_rate_hz");
  return c;
}

VehicleSimService::VehicleSimService(lcm::LCM& lcm, const Clock& clock, const Scenario& scenario,
                                     VehicleSimConfig config, double real_time_factor)
    : node_("vehicle_sim", lcm, clock),
      config_(std::move(config)),
      real_time_factor_(real_time_factor),
      model_(config_.params) {
  model_.set_wind(scenario.wind);
  const TrimResult t = trim(model_, scenario.start_velocity, scenario.start_heading, scenario.wind);
  if (!t.converged)
    throw std::runtime_error("no trim for the start state of " + scenario.file +
                             " (speed beyond the airframe's envelope?)");
  start_state_ = t.state;
  start_state_.position = scenario.start_position;
  trim_controls_ = t.controls;
  model_.set_state(start_state_);
  model_.set_command(trim_controls_);
  released_ = !config_.hold_until_engaged;
  node_.log().info(
      "start trim: collective {:.3f} lon {:.3f} lat {:.3f} pedal {:.3f} rad, "
      "pitch {:.2f} roll {:.2f} deg",
      t.controls.collective, t.controls.lon_cyclic, t.controls.lat_cyclic, t.controls.pedal,
      rad2deg(euler_from_quat(t.state.attitude).y()),
      rad2deg(euler_from_quat(t.state.attitude).x()));

  node_.subscribe<actuator_cmd_t>(
      channels::kActuatorCmd, [this](const actuator_cmd_t& m) { on_command(m); },
      SubscribeOptions{0.5, 0.5});
  node_.subscribe<control_status_t>(
      channels::kControlStatus, [this](const control_status_t& m) { on_control_status(m); },
      SubscribeOptions{1.0, 1.0});
  node_.add_timer(
      1.0 / config_.physics_rate, [this] { step_physics(); }, "physics");
  node_.add_timer(
      1.0 / config_.nav_rate, [this] { publish_nav(); }, "nav");
}

void VehicleSimService::on_command(const actuator_cmd_t& m) {
  last_command_time_ = node_.now();
  // Until released the vehicle flies its trim, whatever the controller says.
  if (released_) model_.set_command({m.collective, m.lon_cyclic, m.lat_cyclic, m.pedal});
}

void VehicleSimService::on_control_status(const control_status_t& m) {
  if (released_) return;
  if (m.mode == control_status_t::WAYPOINT || m.mode == control_status_t::TRAJECTORY) {
    released_ = true;
    node_.log().info("controller engaged at t={:.2f} s: vehicle released", to_seconds(node_.now()));
  }
}

void VehicleSimService::step_physics() {
  const Utime now = node_.now();
  const Utime dt_us = to_utime(1.0 / config_.physics_rate);
  if (state_time_ == INT64_MIN) {
    state_time_ = now;
    hold_started_ = now;
  }
  if (!released_ && now - hold_started_ >= to_utime(config_.engage_timeout)) {
    released_ = true;
    node_.log().warn("no controller engaged within {:.1f} s: vehicle released",
                     config_.engage_timeout);
  }
  // Integrate in whole fixed steps up to the clock; the state is always
  // stamped with the time it is valid for.
  while (state_time_ + dt_us <= now) {
    if (released_) {
      model_.step(to_seconds(dt_us));
    } else {
      // Held: trimmed flight frozen at the start point.
      model_.set_state(start_state_);
    }
    state_time_ += dt_us;
    ++steps_;
  }
  const bool commanded = last_command_time_ != INT64_MIN &&
                         now - last_command_time_ <= to_utime(config_.command_timeout);
  node_.set_state(!released_ ? "holding" : commanded ? "running" : "degraded");
}

void VehicleSimService::publish_nav() {
  if (state_time_ == INT64_MIN) return;
  const RotorcraftState& s = model_.state();
  nav_state_t nav;
  nav.utime = state_time_;
  nav.frame = "NED";
  const Vec3 euler = euler_from_quat(s.attitude);
  const Vec3 accel = released_ ? model_.acceleration() : Vec3::Zero();
  for (int i = 0; i < 3; ++i) {
    nav.position[i] = s.position[i];
    nav.velocity[i] = s.velocity[i];
    nav.acceleration[i] = accel[i];
    nav.euler[i] = euler[i];
    nav.body_rates[i] = s.body_rates[i];
  }
  nav.quaternion[0] = s.attitude.w();
  nav.quaternion[1] = s.attitude.x();
  nav.quaternion[2] = s.attitude.y();
  nav.quaternion[3] = s.attitude.z();
  node_.publish(channels::kNavState, nav);

  sim_clock_t clock;
  clock.utime = state_time_;
  clock.real_time_factor = real_time_factor_;
  clock.step = steps_;
  node_.publish(channels::kSimClock, clock);
}

}  // namespace ofn::vehicle
