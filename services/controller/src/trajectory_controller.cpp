#include "ofn/controller/trajectory_controller.hpp"

#include <algorithm>
#include <cmath>

namespace ofn::control {
namespace {

bool finite(const vehicle::Controls& c) {
  return std::isfinite(c.collective) && std::isfinite(c.lon_cyclic) &&
         std::isfinite(c.lat_cyclic) && std::isfinite(c.pedal);
}

}  // namespace

TrajectoryController::TrajectoryController(vehicle::RotorcraftParams nominal, ControllerGains gains,
                                           std::unique_ptr<AdaptiveElement> adaptive)
    : model_(std::move(nominal)),
      gains_(gains),
      adaptive_(adaptive ? std::move(adaptive) : std::make_unique<NoAdaptation>()) {
  const auto trim = vehicle::trim(model_, Vec3::Zero(), 0.0);
  hover_ = trim.controls;
  hover_.lon_cyclic = 0;
  hover_.lat_cyclic = 0;
  hover_tail_thrust_ = -model_.params().tail_thrust_per_rad * trim.controls.pedal;
  tail_thrust_estimate_ = hover_tail_thrust_;
  actuator_estimate_ = hover_;
  // Lyapunov weights of each axis's error dynamics e'' = -kp e - kd e',
  // A^T P + P A = -I: e^T P B = p12 e + p22 e'.
  auto lyapunov = [](const Vec3& kp, const Vec3& kd, Vec3* p12, Vec3* p22) {
    for (int i = 0; i < 3; ++i) {
      const double a = std::max(kp[i], 1e-3), b = std::max(kd[i], 1e-3);
      (*p12)[i] = 1.0 / (2.0 * a);
      (*p22)[i] = ((*p12)[i] + 0.5) / b;
    }
  };
  lyapunov(gains_.position, gains_.velocity, &outer_p12_, &outer_p22_);
  lyapunov(gains_.attitude, gains_.rate, &inner_p12_, &inner_p22_);
}

void TrajectoryController::reset() {
  position_integral_.setZero();
  attitude_integral_.setZero();
  tail_thrust_estimate_ = hover_tail_thrust_;
  reference_started_ = false;
  actuator_estimate_ = hover_;
  flap_started_ = false;
  adaptive_->reset();
}

double TrajectoryController::collective_for_thrust(double thrust, const Vec3& air_body) const {
  // Invert the nominal blade-element/momentum thrust model: first the
  // induced velocity momentum theory gives for this thrust, then the
  // collective that produces the thrust at that inflow.
  const auto& p = model_.params();
  const double rho_a = p.air_density * p.disk_area();
  const double horizontal = std::hypot(air_body.x(), air_body.y());
  double lo = 0.0, hi = 60.0;
  for (int i = 0; i < 50; ++i) {
    const double vi = 0.5 * (lo + hi);
    const double flow = std::max(0.5, std::hypot(horizontal, vi - air_body.z()));
    (vi - thrust / (2.0 * rho_a * flow) > 0 ? hi : lo) = vi;
  }
  const double vi = 0.5 * (lo + hi);
  const double tip = p.tip_speed();
  const double mu = horizontal / tip;
  const double lambda = (vi - air_body.z()) / tip;
  const double ct = thrust / (rho_a * tip * tip);
  return (2.0 * ct / (p.lift_slope * p.solidity) + 0.5 * lambda) / (1.0 / 3.0 + 0.5 * mu * mu);
}

Vec3 TrajectoryController::angular_accel_for(const vehicle::Controls& c, double thrust,
                                             const Vec3& air_body, const Vec3& w,
                                             double rotor_torque, double flap_lon,
                                             double flap_lat) const {
  const auto& p = model_.params();
  const double moment_per_flap = thrust * p.hub_height + p.flap_stiffness;
  const double tail_flow = air_body.y() - w.z() * p.tail_arm;
  const double tail_thrust = -p.tail_thrust_per_rad * c.pedal - p.tail_velocity_damping * tail_flow;
  const Vec3 moment(moment_per_flap * flap_lat, -moment_per_flap * flap_lon,
                    rotor_torque - p.tail_arm * tail_thrust);
  return (moment - w.cross(p.inertia.cwiseProduct(w))).cwiseQuotient(p.inertia);
}

void TrajectoryController::set_speed_limits(double max_speed, double max_vertical_speed) {
  governed_speed_ = std::isfinite(max_speed) ? std::max(0.0, max_speed) : 0.0;
  governed_vertical_speed_ =
      std::isfinite(max_vertical_speed) ? std::max(0.0, max_vertical_speed) : 0.0;
}

VehicleEstimate predict_estimate(const VehicleEstimate& x, const Vec3& acceleration, double age,
                                 double max_age) {
  VehicleEstimate out = x;
  const double dt = std::isfinite(age) ? std::clamp(age, 0.0, std::max(0.0, max_age)) : 0.0;
  if (dt <= 0.0 || !acceleration.allFinite()) return out;
  out.position += x.velocity * dt + 0.5 * acceleration * (dt * dt);
  out.velocity += acceleration * dt;
  const Vec3 turn = x.body_rates * dt;  // body axes: right-multiplied
  if (turn.norm() > 0.0)
    out.attitude =
        (x.attitude * Quat(Eigen::AngleAxisd(turn.norm(), turn.normalized()))).normalized();
  return out;
}

Vec3 TrajectoryController::govern_speed(const Vec3& accel, const Vec3& velocity) const {
  Vec3 a = accel;
  // The acceleration allowed towards a limit `left` away (negative: over it).
  const auto cap_for = [&](double velocity_gain, double left) {
    return velocity_gain * (left >= 0 ? 1.0 : gains_.governor_over_limit) * left;
  };
  const double speed = velocity.norm();
  if (governed_speed_ > 0 && speed > 1e-6) {
    const Vec3 along = velocity / speed;
    const double cap = cap_for(gains_.velocity.x(), governed_speed_ - speed);
    const double excess = a.dot(along) - cap;
    if (excess > 0) a -= excess * along;
  }
  if (governed_vertical_speed_ > 0) {
    const double climb = std::abs(velocity.z());
    const double sign = velocity.z() >= 0 ? 1.0 : -1.0;
    const double cap = cap_for(gains_.velocity.z(), governed_vertical_speed_ - climb);
    if (sign * a.z() > cap) a.z() = sign * cap;
  }
  return a;
}

// What one step's stages hand on to the next.
struct TrajectoryController::StepSignals {
  double dt = 0;
  Mat3 world_from_body;
  Vec3 air_body;                         // velocity in body axes (no wind is known)
  AdaptiveInputs ad;                     // filled stage by stage, learnt from at the end
  Vec3 rm_accel;                         // outer reference model's acceleration, world
  Vec3 accel_wanted;                     // outer pseudo-control less the adaptive share
  Vec3 accel_inverted;                   // governed, bounded command less the adaptive share
  Vec3 other_world;                      // fuselage drag and tail side force, world, N
  Mat3 r_des;                            // attitude command as a rotation matrix
  Vec3 rm_angular;                       // inner reference model's angular acceleration, body
  Vec3 angular;                          // inner pseudo-control less the adaptive share
  double rotor_torque = 0;               // N m, nominal main-rotor torque
  vehicle::Controls unclamped_controls;  // before the actuator limits
};

ControlOutput TrajectoryController::step(const Reference& ref, const VehicleEstimate& x,
                                         double dt) {
  ControlOutput out;
  StepSignals s;
  s.dt = dt;
  s.ad.dt = dt;
  s.ad.velocity = x.velocity;
  s.ad.body_rates = x.body_rates;
  s.world_from_body = x.attitude.toRotationMatrix();
  s.air_body = s.world_from_body.transpose() * x.velocity;
  s.ad.body_velocity = s.air_body;
  s.ad.gravity_body = s.world_from_body.transpose() * Vec3::UnitZ();
  s.ad.nose_world = s.world_from_body.col(0);

  if (!reference_started_) {
    ref_position_ = x.position;
    ref_velocity_ = x.velocity;
    ref_attitude_ = x.attitude;
    ref_rates_ = x.body_rates;
    reference_started_ = true;
  }

  outer_loop(ref, x, s, &out);
  invert_for_thrust(ref.yaw, s, &out);
  inner_loop(ref.yaw_rate, x, s, &out);
  clamp_to_actuator_limits(&out);
  hedge(x.body_rates, s, &out);
  adaptive_->update(s.ad);
  advance_reference_models(s, &out);

  const bool states_finite = ref_position_.allFinite() && ref_velocity_.allFinite() &&
                             ref_rates_.allFinite() && ref_attitude_.coeffs().allFinite() &&
                             position_integral_.allFinite() && attitude_integral_.allFinite() &&
                             std::isfinite(flap_lon_) && std::isfinite(flap_lat_);
  if (!finite(out.controls) || !out.commanded_accel.allFinite() || !states_finite) {
    out = ControlOutput{};
    out.controls = hover_;
    out.valid = false;
    reset();
  }
  return out;
}

void TrajectoryController::outer_loop(const Reference& ref, const VehicleEstimate& x,
                                      StepSignals& s, ControlOutput* out) {
  const auto& g = gains_;
  AdaptiveInputs& ad = s.ad;
  // The reference model chases the commanded trajectory; the vehicle is
  // made to follow the reference model.
  const double wo = g.outer_reference_frequency;
  s.rm_accel = ref.acceleration + wo * wo * (ref.position - ref_position_) +
               2.0 * g.outer_reference_damping * wo * (ref.velocity - ref_velocity_);
  ad.position_error = ref_position_ - x.position;
  ad.velocity_error = ref_velocity_ - x.velocity;
  for (int i = 0; i < 3; ++i) {
    // Anti-windup: integrate only near the reference (large errors are the
    // proportional term's job, and winding up on them overshoots), and keep
    // the integral's share within its limit.
    if (std::abs(ad.position_error[i]) < g.integral_band)
      position_integral_[i] += ad.position_error[i] * s.dt;
    if (g.integral[i] > 0)
      position_integral_[i] = std::clamp(position_integral_[i], -g.integral_limit / g.integral[i],
                                         g.integral_limit / g.integral[i]);
  }
  ad.pseudo_accel = s.rm_accel + g.position.cwiseProduct(ad.position_error) +
                    g.velocity.cwiseProduct(ad.velocity_error) +
                    g.integral.cwiseProduct(position_integral_);
  ad.outer_error_signal =
      outer_p12_.cwiseProduct(ad.position_error) + outer_p22_.cwiseProduct(ad.velocity_error);
  ad.outer_error_norm = std::hypot(ad.position_error.norm(), ad.velocity_error.norm());
  out->adaptive_accel = adaptive_->outer_output(ad);
  s.accel_wanted = ad.pseudo_accel - out->adaptive_accel;
  // The governor and the bounds shape the acceleration asked of the
  // vehicle; the adaptive share is added after them. It stands for what the
  // nominal model gets wrong (an updraft's extra rotor thrust, a wind the
  // blow-back and drag do not know), not for acceleration flown: bounded
  // with the rest, an updraft of 0.3 g took the whole 3 m/s^2 of descent
  // authority and the vehicle climbed away at full down command
  // (docs/TUNING.md, "The adaptive share outside the pseudo-control bound").
  Vec3 accel = govern_speed(ad.pseudo_accel, x.velocity);
  const Vec3 horizontal = clamp_norm(Vec3(accel.x(), accel.y(), 0.0), g.max_horizontal_accel);
  const double vertical = std::clamp(accel.z(), -g.max_vertical_accel, g.max_vertical_accel);
  out->saturated = (horizontal - Vec3(accel.x(), accel.y(), 0.0)).norm() > 1e-9 ||
                   vertical != accel.z() || (accel - ad.pseudo_accel).norm() > 1e-9;
  accel = Vec3(horizontal.x(), horizontal.y(), vertical);
  out->commanded_accel = accel;
  s.accel_inverted = accel - out->adaptive_accel;
}

void TrajectoryController::invert_for_thrust(double yaw, StepSignals& s, ControlOutput* out) const {
  const auto& p = model_.params();
  // The main rotor must supply m (a - g) less the fuselage drag and the
  // tail rotor's side force (last step's value; it changes slowly).
  const Vec3& air_body = s.air_body;
  const Vec3 drag_body =
      -0.5 * p.air_density * p.drag_area.cwiseProduct(air_body.cwiseAbs()).cwiseProduct(air_body);
  s.other_world = s.world_from_body * (drag_body + Vec3(0.0, tail_thrust_estimate_, 0.0));
  Vec3 force = p.mass * (s.accel_inverted - Vec3(0, 0, kGravity)) - s.other_world;
  // Never ask for less than a fraction of hover thrust or a large tilt.
  if (force.z() > -0.3 * p.mass * kGravity) force.z() = -0.3 * p.mass * kGravity;
  const double max_horizontal = -force.z() * std::tan(gains_.max_tilt);
  const Vec3 fh = clamp_norm(Vec3(force.x(), force.y(), 0.0), max_horizontal);
  force.x() = fh.x();
  force.y() = fh.y();
  out->thrust = force.norm();

  const Vec3 body_z = -force / out->thrust;
  const Vec3 heading(std::cos(yaw), std::sin(yaw), 0.0);
  const Vec3 body_y = body_z.cross(heading).normalized();
  const Vec3 body_x = body_y.cross(body_z);
  s.r_des.col(0) = body_x;
  s.r_des.col(1) = body_y;
  s.r_des.col(2) = body_z;
  out->attitude_command = Quat(s.r_des).normalized();
  out->controls.collective = collective_for_thrust(out->thrust, air_body);
}

void TrajectoryController::inner_loop(double yaw_rate, const VehicleEstimate& x, StepSignals& s,
                                      ControlOutput* out) {
  const auto& p = model_.params();
  const auto& g = gains_;
  AdaptiveInputs& ad = s.ad;
  const Vec3& air_body = s.air_body;
  auto rotation_error = [](const Quat& from, const Quat& to) {
    Quat e = from.conjugate() * to;
    if (e.w() < 0) e.coeffs() = -e.coeffs();  // shortest rotation
    return Vec3(2.0 * e.vec());
  };
  const double wi = g.inner_reference_frequency;
  // The heading turns about the world's vertical; with the disk tilted that
  // is partly a roll and pitch rate in body axes. Leaving those out made the
  // reference attitude lag the command by 2 zeta / w_i under the yaw sweep,
  // and the lagging tilt swung the flown speed.
  const Vec3 rate_command = s.r_des.transpose() * Vec3(0, 0, yaw_rate);
  s.rm_angular = wi * wi * rotation_error(ref_attitude_, out->attitude_command) +
                 2.0 * g.inner_reference_damping * wi * (rate_command - ref_rates_);
  ad.attitude_error = rotation_error(x.attitude, ref_attitude_);
  ad.rate_error = ref_rates_ - x.body_rates;
  attitude_integral_ += ad.attitude_error * s.dt;
  for (int i = 0; i < 3; ++i)
    if (g.attitude_integral[i] > 0)
      attitude_integral_[i] =
          std::clamp(attitude_integral_[i], -g.attitude_integral_limit / g.attitude_integral[i],
                     g.attitude_integral_limit / g.attitude_integral[i]);
  ad.pseudo_angular = s.rm_angular + g.attitude.cwiseProduct(ad.attitude_error) +
                      g.rate.cwiseProduct(ad.rate_error) +
                      g.attitude_integral.cwiseProduct(attitude_integral_);
  ad.inner_error_signal =
      inner_p12_.cwiseProduct(ad.attitude_error) + inner_p22_.cwiseProduct(ad.rate_error);
  ad.inner_error_norm = std::hypot(ad.attitude_error.norm(), ad.rate_error.norm());
  out->adaptive_angular = adaptive_->inner_output(ad);
  s.angular = ad.pseudo_angular - out->adaptive_angular;
  const Vec3& w = x.body_rates;
  const Vec3 moment = p.inertia.cwiseProduct(s.angular) + w.cross(p.inertia.cwiseProduct(w));

  // Rotor moment per radian of disk tilt: thrust offset at the hub plus the
  // hub spring.
  const double moment_per_flap = out->thrust * p.hub_height + p.flap_stiffness;
  const double flap_lat = moment.x() / moment_per_flap;
  const double flap_lon = -moment.y() / moment_per_flap;
  // The disk settles at the cyclic command less blow-back, shifted by the
  // gyroscopic lag under body rates; invert that steady relation.
  out->controls.lon_cyclic =
      (flap_lon - p.flap_time_constant * w.y() + p.flap_blowback * air_body.x()) / p.cyclic_to_flap;
  out->controls.lat_cyclic =
      (flap_lat + p.flap_time_constant * w.x() + p.flap_blowback * air_body.y()) / p.cyclic_to_flap;
  // Yaw: tail thrust balances main-rotor torque and supplies the moment.
  vehicle::RotorcraftState probe;
  probe.attitude = x.attitude;
  probe.velocity = x.velocity;
  probe.body_rates = w;
  probe.actuators.collective = out->controls.collective;
  probe.induced_velocity = model_.steady_induced_velocity(out->controls.collective, air_body);
  vehicle::RotorcraftLoads loads;
  // No wind: the controller knows only the velocity over the ground.
  model_.derivative(probe, probe.actuators, Vec3::Zero(), &loads);
  s.rotor_torque = loads.rotor_torque;
  const double tail_thrust = (loads.rotor_torque - moment.z()) / p.tail_arm;
  // Carried to the next step; one bad input must not poison the ones after.
  if (std::isfinite(tail_thrust)) tail_thrust_estimate_ = tail_thrust;
  const double tail_flow = air_body.y() - w.z() * p.tail_arm;
  out->controls.pedal =
      -(tail_thrust + p.tail_velocity_damping * tail_flow) / p.tail_thrust_per_rad;
  s.unclamped_controls = out->controls;
}

void TrajectoryController::clamp_to_actuator_limits(ControlOutput* out) const {
  const auto& p = model_.params();
  const vehicle::Controls lo = p.min_controls, hi = p.max_controls;
  vehicle::Controls c = out->controls;
  c.collective = std::clamp(c.collective, lo.collective, hi.collective);
  c.lon_cyclic = std::clamp(c.lon_cyclic, lo.lon_cyclic, hi.lon_cyclic);
  c.lat_cyclic = std::clamp(c.lat_cyclic, lo.lat_cyclic, hi.lat_cyclic);
  c.pedal = std::clamp(c.pedal, lo.pedal, hi.pedal);
  if (c.as_array() != out->controls.as_array()) out->saturated = true;
  out->controls = c;
}

void TrajectoryController::hedge(const Vec3& w, const StepSignals& s, ControlOutput* out) {
  const auto& p = model_.params();
  const Vec3& air_body = s.air_body;
  const double dt = s.dt;
  // What the model says the vehicle achieves with these controls, where
  // the servos can have got to, and (outer loop) the attitude it has now
  // rather than the one commanded.
  auto reached = actuator_estimate_.as_array();
  const auto wanted = out->controls.as_array(), rate = p.actuator_rate.as_array();
  for (int i = 0; i < 4; ++i)
    reached[i] = std::clamp(wanted[i], reached[i] - rate[i] * dt, reached[i] + rate[i] * dt);
  const auto achievable = vehicle::Controls::from_array(reached);
  double thrust_achievable = out->thrust;
  if (achievable.collective != s.unclamped_controls.collective)
    thrust_achievable =
        model_.thrust(achievable.collective,
                      model_.steady_induced_velocity(achievable.collective, air_body), air_body);
  // The thrust points along the inner reference model's attitude: the
  // attitude the inner loop is designed to have reached by now. (The actual
  // attitude would also pass on the inner loop's own tracking errors, which
  // its adaptive element is there to remove, and the outer reference model
  // would drift after the vehicle.)
  const Vec3 accel_achievable =
      (-thrust_achievable * ref_attitude_.toRotationMatrix().col(2) + s.other_world) / p.mass +
      Vec3(0, 0, kGravity);
  // The disk follows the cyclic with the flapping lag, which the inversion
  // takes as settled: the tilt the nominal rotor has got to from the
  // servos' positions is what the inner loop can have now. Left out, the
  // lag reached the inner network as a rate error after every step in the
  // attitude command, and at its learning rate the network fed it back
  // into a roll and pitch oscillation of +-0.5 rad with the cyclics swinging
  // limit to limit (docs/TUNING.md, "Flapping lag in the hedge").
  const double lon_steady =
      p.cyclic_to_flap * achievable.lon_cyclic - p.flap_blowback * air_body.x();
  const double lat_steady =
      p.cyclic_to_flap * achievable.lat_cyclic - p.flap_blowback * air_body.y();
  if (!flap_started_) {
    flap_lon_ = lon_steady + p.flap_time_constant * w.y();
    flap_lat_ = lat_steady - p.flap_time_constant * w.x();
    flap_started_ = true;
  }
  const double flap_rate = dt / std::max(p.flap_time_constant, dt);
  flap_lon_ += dt * w.y() - flap_rate * (flap_lon_ - lon_steady);
  flap_lat_ += -dt * w.x() - flap_rate * (flap_lat_ - lat_steady);
  const Vec3 angular_achievable = angular_accel_for(achievable, thrust_achievable, air_body, w,
                                                    s.rotor_torque, flap_lon_, flap_lat_);
  if (gains_.hedging) {
    out->hedge_accel = s.accel_wanted - accel_achievable;
    out->hedge_angular = s.angular - angular_achievable;
  }
  actuator_estimate_ = achievable;
}

void TrajectoryController::advance_reference_models(const StepSignals& s, ControlOutput* out) {
  // The reference models advance by what the vehicle can follow.
  const double dt = s.dt;
  const Vec3 rm_accel_hedged = s.rm_accel - out->hedge_accel;
  ref_position_ += dt * (ref_velocity_ + 0.5 * dt * rm_accel_hedged);
  ref_velocity_ += dt * rm_accel_hedged;
  ref_rates_ += dt * (s.rm_angular - out->hedge_angular);
  const Vec3 turn = ref_rates_ * dt;
  if (turn.norm() > 0)
    ref_attitude_ =
        (ref_attitude_ * Quat(Eigen::AngleAxisd(turn.norm(), turn.normalized()))).normalized();
  out->reference_position = ref_position_;
}

}  // namespace ofn::control
