#pragma once
// The rotorcraft model flown as the simulator's truth: its state advanced
// in time under a command and the wind by fourth-order Runge-Kutta at a
// fixed step. Pure core: no LCM, no clock; step() is given the time step.

#include "ofn/common/frames.hpp"
#include "ofn/rotorcraft_model/rotorcraft_model.hpp"

namespace ofn::vehicle {

/// A RotorcraftModel (the same parameters and equations, so trim() takes
/// it as it is) with a state, a command and a wind.
class RotorcraftSimulation : public RotorcraftModel {
 public:
  explicit RotorcraftSimulation(RotorcraftParams params = {});

  const RotorcraftState& state() const { return state_; }
  void set_state(const RotorcraftState& s) { state_ = s; }
  /// Kinematic acceleration (NED) at the last step.
  const Vec3& acceleration() const { return acceleration_; }
  const RotorcraftLoads& loads() const { return loads_; }

  /// Commanded controls are clamped to the position limits here.
  void set_command(const Controls& command);
  const Controls& command() const { return command_; }
  void set_wind(const Vec3& wind_ned) { wind_ = wind_ned; }

  /// Advances by dt with fourth-order Runge-Kutta.
  void step(double dt);

 private:
  RotorcraftState state_;
  Controls command_;
  Vec3 wind_ = Vec3::Zero();
  Vec3 acceleration_ = Vec3::Zero();
  RotorcraftLoads loads_;
};

}  // namespace ofn::vehicle
