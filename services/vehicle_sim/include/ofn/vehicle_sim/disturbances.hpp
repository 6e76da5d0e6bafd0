#pragma once
// What separates the simulated flight from the controller's idealised world:
// an airframe that differs from the nominal one, Dryden turbulence on top of
// the steady wind, and a navigation solution that is noisy and late. Pure
// core: no LCM, no clock; every random draw comes from seeded streams read
// as raw 32-bit outputs, so a seed gives the same flight on any platform.

#include <cstdint>
#include <deque>
#include <random>

#include "ofn/common/frames.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/vehicle_sim/rotorcraft_simulation.hpp"

namespace ofn::vehicle {

/// Unit-variance Gaussian numbers from a seeded generator (Box-Muller on the
/// raw generator output, not the library's distributions).
class GaussianStream {
 public:
  explicit GaussianStream(uint32_t seed) : rng_(seed) {}
  double next();
  Vec3 next3() {
    const double x = next(), y = next(), z = next();
    return Vec3(x, y, z);
  }

 private:
  double uniform() { return static_cast<double>(rng_()) / 4294967296.0; }
  std::mt19937 rng_;
};

/// Intensities and scale lengths of Dryden turbulence.
struct DrydenParams {
  Vec3 sigma = Vec3::Zero();               // m/s: u (along the path), v (across), w (down)
  Vec3 scale_length = Vec3(200, 200, 50);  // m: L_u, L_v, L_w
};

/// MIL-F-8785C low-altitude model (below 1000 ft): L_w = h,
/// L_u = L_v = h / (0.177 + 0.000823 h)^1.2, sigma_w = 0.1 W20,
/// sigma_u = sigma_v = sigma_w / (0.177 + 0.000823 h)^0.4 (h in ft). The
/// altitude is kept within 10..1000 ft where the form holds.
DrydenParams dryden_low_altitude(double altitude_m, double wind_at_20ft);

/// Dryden gust velocities: u first order, v and w with the (1 + sqrt(3) T s)
/// / (1 + T s)^2 form, T = L / V. Each channel is built from a unit-variance
/// Gauss-Markov state, so its variance is sigma^2 whatever the airspeed does.
class DrydenTurbulence {
 public:
  explicit DrydenTurbulence(uint32_t seed) : noise_(seed) {}
  /// Advances by dt at airspeed (m/s, floored at kMinAirspeed so that a
  /// hover does not freeze the field) and returns the gust, path axes.
  Vec3 step(double dt, double airspeed, const DrydenParams& params);
  const Vec3& gust() const { return gust_; }
  static constexpr double kMinAirspeed = 1.0;

 private:
  GaussianStream noise_;
  Vec3 first_ = Vec3::Zero();   // unit-variance first stage per channel
  Vec3 second_ = Vec3::Zero();  // v, w: the second lag
  Vec3 gust_ = Vec3::Zero();
};

/// What the navigation system reports.
struct NavSample {
  double time = 0;  // s the sample is valid for
  Vec3 position = Vec3::Zero();
  Vec3 velocity = Vec3::Zero();
  Quat attitude = Quat::Identity();
  Vec3 body_rates = Vec3::Zero();
  Vec3 acceleration = Vec3::Zero();
};

/// The flown airframe: the configured one changed by a scenario's
/// `vehicle:` variation (mass, inertia, time constants, actuator authority).
RotorcraftParams apply_variation(RotorcraftParams airframe, const VehicleVariation& variation);

/// Rotorcraft model in its environment: steady wind plus turbulence, and the
/// navigation solution a controller would receive (noise, latency).
class SimulatedVehicle {
 public:
  SimulatedVehicle(const RotorcraftParams& airframe, const Vec3& steady_wind,
                   const Disturbances& disturbances, double ground_altitude = 0);

  /// Puts the vehicle at a state at time t (s) and forgets the nav history.
  void reset(const RotorcraftState& state, double t);
  void set_command(const Controls& c) { model_.set_command(c); }
  /// Advances the turbulence and the airframe by dt.
  void step(double dt);
  /// Holds the airframe at a state (a start hold) while time runs on.
  void hold(const RotorcraftState& state, double dt);

  /// The navigation solution now: the true state `latency` ago plus noise.
  /// Each call draws fresh noise.
  NavSample measure();

  const RotorcraftSimulation& model() const { return model_; }
  double time() const { return time_; }
  /// Air-mass velocity now (steady wind + gust), world NED.
  Vec3 wind() const { return steady_wind_ + gust_ned_; }
  const Vec3& gust() const { return gust_ned_; }
  const DrydenParams& turbulence_params() const { return dryden_; }

 private:
  void record();

  RotorcraftSimulation model_;
  Vec3 steady_wind_;
  Disturbances disturbances_;
  double ground_altitude_;
  double time_ = 0;
  DrydenTurbulence turbulence_;
  DrydenParams dryden_;
  Vec3 gust_ned_ = Vec3::Zero();
  GaussianStream nav_noise_;
  std::deque<NavSample> history_;  // true states, oldest first, for the latency
};

}  // namespace ofn::vehicle
