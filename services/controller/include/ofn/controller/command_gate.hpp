#pragma once
// The controller's last line against a command that would leave the
// envelope, whoever sent it: a planner with a bug, a stale process, or a
// stranger on the bus. Three checks, all against limits that the vehicle's
// own configuration sets, not the messages:
//  - a mission is taken only if its limits stay within the airframe's
//    (speed, vertical speed, acceleration) and every waypoint lies inside
//    the geofence; otherwise the mission flown so far is kept;
//  - an avoidance plan is taken only if every sample stays inside the
//    mission's envelope of Eq. 8 (within the benchmarks' 2 %) and the
//    geofence;
//  - every reference the controller flies, whatever its source, is clamped
//    into that envelope and the fence before the control law sees it.
// Pure core, SI, world NED.

#include <optional>
#include <string>
#include <vector>

#include "ofn/common/envelope.hpp"
#include "ofn/common/mission_types.hpp"
#include "ofn/controller/trajectory_controller.hpp"

namespace ofn::control {

struct CommandGateSettings {
  /// What the airframe may be asked at most, whatever a mission says.
  double max_speed = 10.0;          // m/s
  double max_vertical_speed = 3.0;  // m/s
  double max_accel = 3.0;           // m/s^2, total
  /// The geofence: a box in world NED, m (altitude is -down).
  Vec3 fence_min = Vec3(-2000.0, -2000.0, -150.0);
  Vec3 fence_max = Vec3(2000.0, 2000.0, 50.0);
  /// Share over a mission limit a plan may reach (the benchmarks' 2 %).
  double tolerance = kEnvelopeTolerance;
};

/// Throws std::invalid_argument on settings that cannot be a gate.
void check_settings(const CommandGateSettings& settings);

class CommandGate {
 public:
  explicit CommandGate(CommandGateSettings settings = {});

  const CommandGateSettings& settings() const { return settings_; }
  /// The airframe's limits as mission limits (for the hold before a mission).
  Limits airframe_limits() const;

  /// Why a mission with these limits and waypoints is refused, or nullopt.
  std::optional<std::string> check_mission(const Limits& limits,
                                           const std::vector<Waypoint>& waypoints) const;

  /// Why a plan sampled at `times` (s) is refused under `limits`, or
  /// nullopt. Samples wholly before `from` (s, the present on the plan's
  /// time) are past: the last of them, which the present is interpolated
  /// from, is checked, earlier ones are not, as the RH optimiser's commit
  /// gate checks from the present on.
  std::optional<std::string> check_plan(const std::vector<double>& times,
                                        const std::vector<Reference>& samples, const Limits& limits,
                                        double from = 0.0) const;

  /// `reference` inside the fence and the envelope of `limits` (plus the
  /// tolerance); `clamped` says whether anything was changed.
  Reference clamp(const Reference& reference, const Limits& limits, bool* clamped) const;

 private:
  bool inside_fence(const Vec3& position) const;

  CommandGateSettings settings_;
};

}  // namespace ofn::control
