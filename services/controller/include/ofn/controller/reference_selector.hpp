#pragma once
// What the controller flies when the RH optimiser's plans change or stop:
//  - a new avoidance reference is taken only if it starts on the reference
//    flown now, or on the vehicle (the optimiser restarts a plan at the
//    measured state when the vehicle is far off its plan); any other start
//    is a jump, refused with a reason, and the reference flown is kept;
//  - once avoidance has overridden guidance, a reference that goes stale
//    (a dead, stopped or cut-off optimiser) is not followed by waypoint
//    guidance, which would fly the blocked leg: the controller flies the
//    stop of braking.hpp from the reference it was flying, the same stop
//    the optimiser checked before it committed that plan, and then hovers,
//    until a fresh plan or the optimiser's hand-back (NOMINAL) arrives.
// Pure core, SI, world NED; time in seconds of the caller's clock.

#include <optional>
#include <string>

#include "ofn/common/braking.hpp"
#include "ofn/controller/trajectory_controller.hpp"

namespace ofn::control {

struct SelectorSettings {
  double jump_position = 0.5;  // m a new plan may start off the reference flown now
  double jump_velocity = 0.5;  // m/s
  /// A plan restarted at the vehicle: within this of the measured state
  /// (the optimiser starts it at a NAV_STATE a few ms old). Wider, a plan
  /// that an optimiser resumed after a stall starts from where its old plan
  /// has got to, a metre or two ahead of a vehicle that has been braking.
  double resync_position = 0.75;     // m
  double resync_velocity = 0.5;      // m/s
  double stop_accel_fraction = 0.8;  // of the acceleration limit (the optimiser's braking)
  /// m/s^2 of the hold before any mission (there is no limit yet): a stop
  /// from the vehicle's state rather than a step to zero speed. In the
  /// simulator, which freezes the vehicle in trimmed cruise until the
  /// controller has a mission, the command still reaches its bound while
  /// the stop runs ahead of the frozen vehicle.
  double hold_deceleration = 0.4;
  /// s without a reference flown (the control loop stalled, navigation was
  /// lost) after which the reference is not taken up again: the vehicle
  /// has flown on without commands and the reference, or a plan made along
  /// it, may be tens of metres away.
  double lapse_time = 0.2;
};

class ReferenceSelector {
 public:
  explicit ReferenceSelector(SelectorSettings settings = {}) : settings_(settings) {}

  /// A new avoidance plan whose state now is `offered`, while the reference
  /// flown now is `flown` (nullopt before any) and the vehicle is at
  /// (position, velocity). Returns the reason it is refused, or nullopt.
  std::optional<std::string> check_start(const Reference& offered,
                                         const std::optional<Reference>& flown,
                                         const Vec3& position, const Vec3& velocity) const;

  /// An avoidance plan is being flown (set on every accepted plan).
  void plan_flown() {
    avoiding_ = true;
    stop_.reset();
  }
  /// The optimiser handed back (NOMINAL) or a new mission began.
  void hand_back() {
    avoiding_ = false;
    stop_.reset();
  }
  /// A stop flown for another reason (guidance held back) has ended.
  void end_stop() { stop_.reset(); }
  /// No reference has been flown for `gap` seconds: long enough that what
  /// follows starts from the vehicle's state, not from the reference.
  bool lapsed(double gap) const { return gap > settings_.lapse_time; }
  bool avoiding() const { return avoiding_; }
  bool stopping() const { return stop_.has_value(); }

  /// The reference while the plan is stale: the stop from `flown` (the
  /// reference of the last step) begun at the first call, at `max_accel`
  /// times stop_accel_fraction, then the hover at its end.
  Reference safe_stop(double now, const Reference& flown, double max_accel);

  /// The reference without a mission: the stop from the vehicle's state
  /// where the hold `begins` at hold_deceleration, then the hover there.
  Reference hold(double now, const Vec3& position, const Vec3& velocity, bool begins);

 private:
  static Reference along(const StopProfile& stop, double t);

  SelectorSettings settings_;
  bool avoiding_ = false;
  std::optional<StopProfile> stop_;
  double stop_start_ = 0;
  StopProfile hold_;
  double hold_start_ = 0;
};

}  // namespace ofn::control
