#pragma once
// When avoidance takes over from nominal waypoint guidance and when it hands
// back (paper 2.1), and where the receding horizon ends (Eq. 6). Pure core.
//
// Nominal guidance from where the vehicle is means: rejoin the leg a little
// ahead, then fly along it. Avoidance engages as soon as that path, within
// sensor range, passes closer to a detected obstacle than the clearance. It
// hands back only when that path has been clear for a while AND the vehicle
// is back near the leg: waypoint guidance resumes from the vehicle along the
// rejoin segment, which is short and shallow only near the leg.

#include "ofn/common/frames.hpp"
#include "ofn/map/heightfield.hpp"
#include "ofn/rh_optimizer/rh_optimizer.hpp"

namespace ofn::rh {

struct SwitchSettings {
  double engage_margin = 0.5;      // m beyond the clearance the nominal path must keep
  double check_spacing = 1.0;      // m between checked points of the nominal path
  double handback_distance = 0.3;  // m from the leg within which avoidance may hand back
  double handback_hold = 1.0;      // s the nominal path must stay clear before handing back
  /// m/s; while avoidance is stopping the vehicle at the last waypoint, it
  /// hands back only this slow: guidance resumed faster, close to the
  /// waypoint, could not brake in time and would overshoot it.
  double handback_stop_speed = 0.3;
};

/// The straight leg (world NED) the nominal guidance flies.
struct Leg {
  Vec3 from = Vec3::Zero();
  Vec3 to = Vec3::Zero();
};

struct NominalCheck {
  double least_clearance = 0;    // m, closest approach along the nominal path
  double conflict_distance = 0;  // m along the path to the first point closer than required
                                 // (infinity when there is none)
};

/// The nominal path from `position`: the rejoin segment to the leg
/// kGuidanceRejoinDistance ahead of the vehicle's projection, then the leg up to
/// `lookahead` ahead of the projection or its end, checked against
/// `required` clearance.
NominalCheck check_nominal_path(const ClearanceQuery& clearance, const Leg& leg,
                                const Vec3& position, double lookahead, double required,
                                const SwitchSettings& settings);

/// Distance from the vehicle to the leg's line.
double cross_track_distance(const Leg& leg, const Vec3& position);

/// Eq. 6's terminal x in the guidance frame: the nearer of the farthest
/// detected obstacle ahead (plus `beyond`, so the horizon ends past it) and
/// the sensor's reach, never beyond `x_max` (the target) and never closer
/// than `min_horizon` ahead of the vehicle (nor beyond x_max even then).
/// Obstacle cells are those of `grid` above 0 within sensor_range of the
/// vehicle horizontally.
double terminal_x(const GuidanceFrame& frame, const mapping::Heightfield& grid,
                  const Vec3& position, double sensor_range, double beyond, double x_max,
                  double min_horizon);

/// Before an engagement has published anything, a step that can only
/// brake is deferred (nominal guidance flies on, and the next step tries
/// again, typically with the global route the new obstacle is about to
/// produce) while the conflict lies farther along the nominal path than the
/// stop from `velocity` at `deceleration` (braking.hpp) plus `margin` (m).
bool defer_first_brake(double conflict_distance, const Vec3& velocity, double deceleration,
                       double margin);

class AvoidanceSwitch {
 public:
  explicit AvoidanceSwitch(SwitchSettings settings = {}) : settings_(settings) {}

  /// One decision at `time` (s). conflict: the nominal path is too close to
  /// an obstacle now. cross_track: the vehicle's distance from the leg (m).
  /// stopping_speed: its speed while avoidance is stopping it at the last
  /// waypoint, 0 otherwise. at_last_waypoint: avoidance is stopping the
  /// vehicle at the last waypoint and it is inside the waypoint's capture
  /// radius; near the leg or not, guidance may then
  /// take over (its rejoin goes straight to the waypoint, the nominal path
  /// checked), so that a stop that ended a little beside the leg's line is
  /// not held for ever. Returns whether avoidance is engaged after it.
  bool update(double time, bool conflict, double cross_track, double stopping_speed = 0.0,
              bool at_last_waypoint = false);
  bool engaged() const { return engaged_; }
  void reset() {
    engaged_ = false;
    clear_since_ = -1;
  }
  const SwitchSettings& settings() const { return settings_; }

 private:
  SwitchSettings settings_;
  bool engaged_ = false;
  double clear_since_ = -1;  // s; time the nominal path became clear while engaged
};

}  // namespace ofn::rh
