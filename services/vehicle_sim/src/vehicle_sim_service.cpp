#include "ofn/vehicle_sim/vehicle_sim_service.hpp"

#include <cmath>
#include <string>
#include <vector>

#include "ofn/common/channels.hpp"
#include "ofn/common/message_checks.hpp"
#include "ofn/common/message_names.hpp"
#include "ofn/common/obstacle_messages.hpp"
#include "ofn/common/validate/actuator_cmd.hpp"
#include "ofn/common/validate/control_status.hpp"
#include "ofn/common/validate/virtual_obstacles.hpp"
#include "ofn/lidar_scan_t.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/sim_clock_t.hpp"

namespace ofn::vehicle {
namespace {

static_assert(kLidarOk == lidar_scan_t::OK && kLidarNoReturn == lidar_scan_t::NO_RETURN &&
                  kLidarSaturated == lidar_scan_t::SATURATED &&
                  kLidarMaxRange == lidar_scan_t::MAX_RANGE,
              "beam status codes must match lidar_scan_t");

LidarConfig load_lidar_config(YamlReader& r) {
  LidarConfig c;
  c.enabled = r.boolean("enabled", c.enabled);
  c.scan_rate = r.number_in("scan_rate_hz", c.scan_rate, 0.1, 100.0);
  c.layers = r.integer("layers", c.layers);
  if (c.layers < 1 || c.layers > 16) r.fail("layers", "expected 1 to 16 layers");
  c.layer_spacing = deg2rad(r.number_in("layer_spacing_deg", rad2deg(c.layer_spacing), 0.0, 10.0));
  c.elevation_min =
      deg2rad(r.number_in("elevation_min_deg", rad2deg(c.elevation_min), -90.0, 90.0));
  c.elevation_max =
      deg2rad(r.number_in("elevation_max_deg", rad2deg(c.elevation_max), -90.0, 90.0));
  if (c.elevation_max < c.elevation_min)
    r.fail("elevation_max_deg", "must not be below elevation_min_deg");
  c.angular_resolution =
      deg2rad(r.number_in("angular_resolution_deg", rad2deg(c.angular_resolution), 0.01, 10.0));
  c.max_range = r.number_in("max_range", c.max_range, 0.0, 10000.0);
  c.min_range = r.number_in("min_range", c.min_range, 0.0, 100.0);
  if (c.max_range > 0 && c.min_range >= c.max_range) r.fail("min_range", "must be below max_range");
  c.range_noise_sigma = r.number_in("range_noise_sigma", c.range_noise_sigma, 0.0, 10.0);
  c.dropout_probability = r.number_in("dropout_probability", c.dropout_probability, 0.0, 1.0);
  c.outlier_probability = r.number_in("outlier_probability", c.outlier_probability, 0.0, 1.0);
  c.saturation_range = r.number_in("saturation_range", c.saturation_range, 0.0, 100.0);
  c.saturation_probability =
      r.number_in("saturation_probability", c.saturation_probability, 0.0, 1.0);
  const int seed = r.integer("seed", static_cast<int>(c.seed));
  if (seed < 0) r.fail("seed", "expected a whole number >= 0");
  c.seed = static_cast<uint32_t>(seed);
  const auto offset = r.numbers("mount_offset", {0.0, 0.0, 0.0});
  c.mount_offset = Vec3(offset[0], offset[1], offset[2]);
  const auto rpy = r.numbers("mount_rpy_deg", {0.0, 0.0, 0.0});
  c.mount_rpy = Vec3(deg2rad(rpy[0]), deg2rad(rpy[1]), deg2rad(rpy[2]));
  r.finish();
  const double steps = std::round((c.elevation_max - c.elevation_min) / c.angular_resolution) + 1;
  if (steps * c.layers > MessageLimits::kMaxBeams)
    r.fail("angular_resolution_deg",
           "too fine: a scan would exceed " + std::to_string(MessageLimits::kMaxBeams) + " beams");
  return c;
}

}  // namespace

VehicleSimConfig load_vehicle_sim_config(YamlReader& r) {
  VehicleSimConfig c;
  c.physics_rate = r.number_in("physics_rate_hz", c.physics_rate, 200.0, 5000.0);
  c.nav_rate = r.number_in("nav_rate_hz", c.nav_rate, 10.0, 1000.0);
  c.command_timeout = r.number_in("command_timeout", c.command_timeout, 0.0, 60.0);
  c.hold_until_engaged = r.boolean("hold_until_engaged", c.hold_until_engaged);
  c.engage_timeout = r.number_in("engage_timeout", c.engage_timeout, 0.0, 3600.0);
  c.checkpoint_period = r.number_in("checkpoint_period", c.checkpoint_period, 0.01, 60.0);
  YamlReader airframe = r.child("airframe");
  auto& p = c.params;
  p.mass = airframe.number_in("mass", p.mass, 1.0, 1e4);
  const auto inertia =
      airframe.numbers_in("inertia", {p.inertia.x(), p.inertia.y(), p.inertia.z()}, 1e-3, 1e5);
  p.inertia = Vec3(inertia[0], inertia[1], inertia[2]);
  p.flap_time_constant = airframe.number_in("flap_time_constant", p.flap_time_constant, 0.01, 2.0);
  p.inflow_time_constant =
      airframe.number_in("inflow_time_constant", p.inflow_time_constant, 0.01, 2.0);
  p.servo_time_constant =
      airframe.number_in("servo_time_constant", p.servo_time_constant, 0.001, 1.0);
  const double rate = airframe.number_in("actuator_rate", p.actuator_rate.collective, 0.01, 100.0);
  p.actuator_rate = {rate, rate, rate, rate};
  airframe.finish();
  YamlReader lidar = r.child("lidar");
  c.lidar = load_lidar_config(lidar);
  r.finish();
  if (c.nav_rate > c.physics_rate) r.fail("nav_rate_hz", "must not exceed physics_rate_hz");
  return c;
}

VehicleSimService::VehicleSimService(lcm::LCM& lcm, const Clock& clock, const Scenario& scenario,
                                     VehicleSimConfig config, double real_time_factor,
                                     std::optional<VehicleCheckpoint> resume)
    : node_("vehicle_sim", lcm, clock),
      config_(std::move(config)),
      real_time_factor_(real_time_factor),
      vehicle_(apply_variation(config_.params, scenario.vehicle), scenario.wind,
               scenario.disturbances, scenario.ground_altitude),
      // The airframe's stabiliser is built for the configured airframe; a
      // scenario's variation is what it flies.
      failsafe_(config_.params, config_.command_timeout),
      world_({}, scenario.ground_altitude),
      lidar_(config_.lidar, scenario.limits.sensor_range) {
  const TrimResult t =
      trim(vehicle_.model(), scenario.start_velocity, scenario.start_heading, scenario.wind);
  if (!t.converged)
    throw ConfigError("no trim for the start state of " + scenario.file +
                      " (speed beyond the airframe's envelope?)");
  start_state_ = t.state;
  start_state_.position = scenario.start_position;
  trim_controls_ = t.controls;
  vehicle_.reset(start_state_, 0.0);
  vehicle_.set_command(trim_controls_);
  released_ = !config_.hold_until_engaged;
  if (resume) {
    resume_ = *resume;
    released_ = resume->released;
  }
  const auto& v = scenario.vehicle;
  const auto& d = scenario.disturbances;
  if (v.mass_scale != 1.0 || v.inertia_scale != Vec3::Ones() || v.actuator_time_scale != 1.0)
    node_.log().info(
        "airframe varied: mass x{:.2f}, inertia x[{:.2f} {:.2f} {:.2f}], "
        "time constants x{:.2f}",
        v.mass_scale, v.inertia_scale.x(), v.inertia_scale.y(), v.inertia_scale.z(),
        v.actuator_time_scale);
  if (d.turbulence.active())
    node_.log().info("Dryden turbulence on (seed {}), W20 {:.1f} m/s", d.seed,
                     d.turbulence.wind_at_20ft);
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
  // The obstacle injector sends the obstacles present now; until its first
  // message the scanner sees the bare ground.
  node_.subscribe<virtual_obstacles_t>(
      channels::kVirtualObstacles,
      [this](const virtual_obstacles_t& m) { on_virtual_obstacles(m); },
      SubscribeOptions{5.0, 5.0});
  if (config_.lidar.enabled)
    node_.log().info("lidar: {} beams per scan at {:.1f} Hz, max range {:.1f} m",
                     lidar_.beams_per_scan(), config_.lidar.scan_rate, lidar_.max_range());
  node_.add_timer(
      1.0 / config_.physics_rate, [this] { step_physics(); }, "physics");
  node_.add_timer(
      1.0 / config_.nav_rate, [this] { publish_nav(); }, "nav");
}

void VehicleSimService::on_command(const actuator_cmd_t& m) {
  // Beyond the configured airframe's actuator range no healthy controller
  // commands: refused. A scenario's degraded servo (a narrower range) still
  // saturates, as a real one does.
  const Controls command{m.collective, m.lon_cyclic, m.lat_cyclic, m.pedal};
  if (const auto why = controls_beyond_limits(command, config_.params)) {
    node_.reject(channels::kActuatorCmd, *why);
    return;
  }
  last_command_time_ = node_.now();
  if (failsafe_.command_received(to_seconds(last_command_time_)))
    node_.log().info(
        "actuator commands again at t={:.2f} s: the airframe's stabiliser hands back after "
        "{:.2f} s",
        to_seconds(last_command_time_), to_seconds(last_command_time_) - failsafe_.engaged_since());
  // Until released the vehicle flies its trim, whatever the controller says.
  if (released_) vehicle_.set_command(command);
}

void VehicleSimService::on_control_status(const control_status_t& m) {
  if (released_) return;
  // A controller with a mission flies the vehicle, whatever its mode: held
  // back for the planner's first word it flies its hold (a stop from the
  // start speed), and that stop must move the vehicle as it moves the
  // reference. Released only at WAYPOINT or TRAJECTORY, a late first plan
  // left the vehicle frozen while the hold's reference drifted up to a
  // stopping distance ahead, and the first plan then began that far away.
  if (m.mission_id >= 0) {
    released_ = true;
    node_.log().info("controller engaged at t={:.2f} s ({}): vehicle released",
                     to_seconds(node_.now()), control_mode_name(m.mode));
  }
}

void VehicleSimService::on_virtual_obstacles(const virtual_obstacles_t& m) {
  std::vector<ObstacleSpec> specs;
  specs.reserve(m.obstacles.size());
  for (const auto& o : m.obstacles) specs.push_back(from_message(o));
  world_.set_ground_altitude(m.ground_altitude);
  world_.set_obstacles(specs);
  if (m.revision != obstacle_revision_) {
    obstacle_revision_ = m.revision;
    node_.log().info("virtual obstacles revision {}: {} obstacles", m.revision, specs.size());
  }
}

void VehicleSimService::publish_scan(const LidarScan& scan) {
  lidar_scan_t msg;
  msg.utime = scan.utime;
  msg.scan_index = scan.scan_index;
  msg.max_range = scan.max_range;
  msg.num_beams = static_cast<int32_t>(scan.beams.size());
  msg.beam_dt_us.reserve(scan.beams.size());
  msg.elevation.reserve(scan.beams.size());
  msg.layer_angle.reserve(scan.beams.size());
  msg.range.reserve(scan.beams.size());
  msg.status.reserve(scan.beams.size());
  for (const LidarBeam& b : scan.beams) {
    msg.beam_dt_us.push_back(b.dt_us);
    msg.elevation.push_back(b.elevation);
    msg.layer_angle.push_back(b.layer_angle);
    msg.range.push_back(b.range);
    msg.status.push_back(b.status);
  }
  node_.publish(channels::kLidarRaw, msg);
  ++scans_published_;
}

void VehicleSimService::step_physics() {
  const Utime now = node_.now();
  const Utime dt_us = to_utime(1.0 / config_.physics_rate);
  if (state_time_ == INT64_MIN && resume_) {
    // The same flight, on: the state and the time it was saved at (the
    // clock starts there), the controls as they stood.
    state_time_ = resume_->time_us;
    hold_started_ = state_time_;
    steps_ = resume_->steps;
    vehicle_.reset(resume_->state, to_seconds(state_time_));
    vehicle_.set_command(resume_->state.actuators);
    const Vec3& p = resume_->state.position;
    node_.log().warn(
        "resumed from the checkpoint at t={:.2f} s: position ({:.1f}, {:.1f}, {:.1f}) m, "
        "speed {:.2f} m/s, {}",
        to_seconds(state_time_), p.x(), p.y(), p.z(), resume_->state.velocity.norm(),
        released_ ? "released" : "holding");
  } else if (state_time_ == INT64_MIN) {
    state_time_ = now;
    hold_started_ = now;
    vehicle_.reset(start_state_, to_seconds(now));
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
      // No command for command_timeout: the airframe's own stabiliser flies.
      const int takeovers = failsafe_.takeovers();
      if (const auto c = failsafe_.update(to_seconds(state_time_), vehicle_.model().state()))
        vehicle_.set_command(*c);
      if (failsafe_.takeovers() != takeovers)
        node_.log().warn(
            "no actuator command for {:.2f} s at t={:.2f} s: the airframe's stabiliser takes "
            "over (takeover {}), levelling and slowing to a hover",
            to_seconds(state_time_ - last_command_time_), to_seconds(state_time_),
            failsafe_.takeovers());
      vehicle_.step(to_seconds(dt_us));
    } else {
      // Held: trimmed flight frozen at the start point.
      vehicle_.hold(start_state_, to_seconds(dt_us));
    }
    state_time_ += dt_us;
    ++steps_;
    if (config_.lidar.enabled) {
      const RotorcraftState& s = vehicle_.model().state();
      lidar_.advance(state_time_, s.position, s.attitude, world_);
      while (auto scan = lidar_.take_completed_scan()) publish_scan(*scan);
    }
  }
  // Commands older than the failsafe's timeout (0.5 s without a failsafe)
  // are reported, and the stabiliser's flight is.
  const double silent_after = config_.command_timeout > 0 ? config_.command_timeout : 0.5;
  const bool commanded =
      last_command_time_ != INT64_MIN && now - last_command_time_ <= to_utime(silent_after);
  node_.set_state(!released_            ? "holding"
                  : failsafe_.engaged() ? "failsafe"
                  : commanded           ? "running"
                                        : "degraded");
}

void VehicleSimService::publish_nav() {
  if (state_time_ == INT64_MIN) return;
  // The navigation solution is stamped with the time it is valid for: with
  // latency, that is older than the state.
  const NavSample s = vehicle_.measure();
  nav_state_t nav;
  nav.utime = state_time_ - to_utime(vehicle_.time() - s.time);
  nav.frame = "NED";
  const Vec3 euler = euler_from_quat(s.attitude);
  const Vec3 accel = released_ ? s.acceleration : Vec3::Zero();
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

  if (checkpoint_sink_ && (last_checkpoint_ == INT64_MIN ||
                           state_time_ - last_checkpoint_ >= to_utime(config_.checkpoint_period))) {
    last_checkpoint_ = state_time_;
    try {
      checkpoint_sink_(VehicleCheckpoint{state_time_, steps_, released_, vehicle_.model().state()});
      checkpoint_failing_ = false;
    } catch (const std::exception& e) {
      // The flight goes on without it; said once per run of failures.
      if (!checkpoint_failing_) node_.log().warn("checkpoint not saved: {}", e.what());
      checkpoint_failing_ = true;
    }
  }
}

void VehicleSimService::set_checkpoint_sink(CheckpointSink sink) {
  checkpoint_sink_ = std::move(sink);
}

}  // namespace ofn::vehicle
