#pragma once
// Figures of merit of one flight from its navigation and control-status
// samples. Pure core: plain vectors in, a summary out.

#include <optional>
#include <string>
#include <vector>

#include "ofn/common/frames.hpp"
#include "ofn/common/scenario.hpp"

namespace ofn::report {

struct NavSample {
  double t = 0;  // s since the first navigation sample
  Vec3 position, velocity, acceleration, euler, body_rates;
};

struct StatusSample {
  double t = 0;
  int mode = 0;
  int mission_id = -1;
  int active_waypoint = -1;
  Vec3 ref_position, ref_velocity, ref_acceleration, commanded_accel, position_error;
  double yaw_reference = 0;
};

struct FlightSummary {
  double duration = 0;                 // s of navigation data
  bool reached_last_waypoint = false;  // controller reported DONE
  bool crossed_finish = false;
  std::optional<double> gate_start_time, gate_finish_time;  // s
  std::optional<double> gate_to_gate;                       // s
  double max_speed = 0;                                     // m/s, whole flight
  double max_vertical_speed = 0;                            // m/s
  /// m/s, least velocity along the course (north) between the gates; the
  /// limits ask for >= 0. Zero without both gates.
  double min_forward_speed = 0;
  /// m/s^2, largest |acceleration| the trajectory source (waypoint guidance
  /// or the RH optimiser) commanded while the plan was flown: the quantity
  /// the planners' acceleration limit applies to (paper Eq. 8).
  double max_commanded_accel = 0;
  double max_commanded_accel_fraction = 0;  // of limits.max_accel
  /// m/s^2, largest |outer-loop pseudo-control|: the command plus the
  /// controller's feedback corrections.
  double max_pseudo_control = 0;
  double tracking_rms = 0;  // m, |reference - actual| while flying the plan
  double tracking_max = 0;  // m
};

/// The benchmark rule (../shared/BENCHMARKS.md, "What a run reports"): a
/// run fails if it misses the finish gate, comes closer than 0.8 R_s to a
/// real surface, or leaves a limit by more than 2 %.
struct Verdict {
  bool success = false;
  std::vector<std::string> failures;  // one line per broken rule, empty on success
};
constexpr double kLimitTolerance = 0.02;     // share by which a limit may be exceeded
constexpr double kClearanceFailShare = 0.8;  // of R_s

/// `min_clearance` is the least true clearance (none: no obstacles);
/// `has_finish_gate` false judges a flight without gates by its limits and
/// clearance alone.
Verdict judge_flight(const FlightSummary& s, const Limits& limits,
                     std::optional<double> min_clearance, bool has_finish_gate);

/// Time at which the north coordinate first reaches `x` (linear
/// interpolation between samples), or nullopt.
std::optional<double> crossing_time(const std::vector<NavSample>& nav, double x);

FlightSummary analyse_flight(const std::vector<NavSample>& nav,
                             const std::vector<StatusSample>& status, const Limits& limits,
                             std::optional<double> start_gate, std::optional<double> finish_gate);

}  // namespace ofn::report
