#pragma once
// Figures of merit of one flight from its navigation and control-status
// samples, and the benchmark verdict on them. Pure core: plain vectors (and
// the true world, for the clearance) in, a summary and a verdict out.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "ofn/common/frames.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/world/world.hpp"

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
  /// m/s, least velocity along the course (north) between the gates, outside
  /// the recovery spans; the limits ask for >= 0. Zero without both gates.
  double min_forward_speed = 0;
  double recovery_time = 0;  // s of the flight in a dead-end recovery
  /// m/s, largest speed over the last kHoverWindow of navigation data;
  /// none when the data is shorter than that. Tells a hover at the end.
  std::optional<double> final_max_speed;
  /// m/s^2, largest |acceleration| the trajectory source (waypoint guidance
  /// or the RH optimiser) commanded while the plan was flown: the quantity
  /// the planners' acceleration limit applies to (paper Eq. 8).
  double max_commanded_accel = 0;
  double max_commanded_accel_fraction = 0;  // of limits.max_accel
  /// m/s^2, largest |outer-loop pseudo-control|: the command plus the
  /// controller's feedback corrections.
  double max_pseudo_control = 0;
  /// m/s^2, largest north-east norm and largest |down| part of the
  /// pseudo-control: the two parts the controller clamps, each to its bound.
  double max_pseudo_control_horizontal = 0;
  double max_pseudo_control_vertical = 0;
  /// m, largest step of the reference position between consecutive
  /// CONTROL_STATUS samples beyond what the reference velocity explains
  /// (trapezoidal), while the plan is flown: a discontinuity in the plan.
  /// Measured against the reference's own motion, so it does not grow with
  /// speed or with a sample that went missing. A step that lands the
  /// reference on the vehicle (the controller taking over from the
  /// vehicle's state: a lapsed reference, a plan restarted at the measured
  /// state) is no discontinuity to follow; it is counted in
  /// reference_resyncs instead.
  double max_ref_position_jump = 0;
  std::optional<double> max_ref_position_jump_t;  // s, time of the later sample
  /// m/s, the same for the reference velocity against its acceleration.
  double max_ref_velocity_jump = 0;
  /// Steps beyond kMaxReferenceJump after which the reference was within
  /// kMaxReferenceJump of the vehicle.
  int reference_resyncs = 0;
  double tracking_rms = 0;  // m, |reference - actual| while flying the plan
  double tracking_max = 0;  // m
};

/// What the controller clamps its outer-loop pseudo-control to (controller
/// config outer_loop.max_horizontal_accel and max_vertical_accel). The
/// published command must stay inside; beyond it the clamp did not hold.
struct PseudoControlBound {
  double horizontal = 0;  // m/s^2, norm of the north-east part
  double vertical = 0;    // m/s^2, |down part|
};

/// The controller's actuator stops (its config's nominal_airframe
/// min_controls / max_controls), per channel: collective, longitudinal
/// cyclic, lateral cyclic, pedal (rad).
struct ControlStops {
  std::array<double, 4> min{};
  std::array<double, 4> max{};
};

/// How much of the flight the controller asked for all a channel has: the
/// share of ACTUATOR_CMD samples with the channel at a stop. Not a verdict
/// rule but a measure of the authority a flight used up: the seven courses
/// and calm dense fields have the cyclic at a stop well under 1 % of the
/// time, a gusty field far more (docs/RESULTS.md), and while it is there the
/// controller cannot hold the reference, whatever it was planned with.
struct ControlSaturation {
  size_t samples = 0;
  std::array<double, 4> share{};  // per channel, 0..1
  double cyclic_share = 0;        // either cyclic channel at a stop
  double any_share = 0;           // any channel at a stop
};
/// A channel is at a stop within kStopBand of its range from it.
constexpr double kStopBand = 0.005;
/// Commands in the channel order of ControlStops; non-finite ones count as
/// at no stop.
ControlSaturation control_saturation(const std::vector<std::array<double, 4>>& commands,
                                     const ControlStops& stops);

/// The three ways a run ends (../shared/BENCHMARKS.md, "What a run
/// reports").
enum class Outcome {
  kSuccess,   // goal reached (finish gate crossed), no rule broken
  kSafeStop,  // goal not reached, no rule broken, hovering at the end
  kFailure,   // a rule broken, or neither of the above
};
/// "success", "safe_stop", "failure": the words of the reports.
const char* to_string(Outcome outcome);

/// The benchmark rule applied to one flight. `failures` holds one line per
/// broken rule (and the missed goal, unless the run is a safe stop); it is
/// empty unless the outcome is kFailure.
struct Verdict {
  Outcome outcome = Outcome::kFailure;
  bool success = false;  // outcome == Outcome::kSuccess
  std::vector<std::string> failures;
};
constexpr double kLimitTolerance = 0.02;     // share by which a limit may be exceeded
constexpr double kClearanceFailShare = 0.8;  // of R_s
/// m between consecutive CONTROL_STATUS samples (50 Hz): a larger jump of
/// the reference position is a discontinuity the vehicle cannot follow.
constexpr double kMaxReferenceJump = 1.0;
/// A run ends at a hover when its speed stayed below kHoverSpeed over the
/// last kHoverWindow of the flight.
constexpr double kHoverSpeed = 0.3;   // m/s
constexpr double kHoverWindow = 2.0;  // s

/// How lengths appear in the failure lines (the scenario's display unit).
struct DisplayUnit {
  std::string name = "m";
  double metres_per_unit = 1.0;
};

/// `min_clearance` is the least true clearance to the obstacles and the
/// ground (none: no world known); `has_finish_gate` false makes the last
/// waypoint (controller DONE) the goal instead of the finish gate.
Verdict judge_flight(const FlightSummary& s, const Limits& limits,
                     const PseudoControlBound& pseudo_control_bound,
                     std::optional<double> min_clearance, bool has_finish_gate,
                     const DisplayUnit& unit = {});

/// Least true clearance of a flight: from each navigation sample to the
/// nearest real surface, the obstacles present at that time and the ground.
struct Clearance {
  double distance = 0;     // m
  double t = 0;            // s, when it was least
  bool to_ground = false;  // the nearest surface then was the ground
};
/// None without navigation samples.
std::optional<Clearance> least_clearance(const std::vector<NavSample>& nav,
                                         const world::World& truth);

/// Time at which the north coordinate first reaches `x` (linear
/// interpolation between samples), or nullopt.
std::optional<double> crossing_time(const std::vector<NavSample>& nav, double x);

/// True for the controller modes in which it flies a plan (waypoint
/// guidance, a REF_TRAJ, and any mode added later to fly one): every mode
/// but holding before a mission, lost navigation and holding after arrival.
bool flies_a_plan(int mode);

/// A time span (s, the navigation samples' clock) in which the RH optimiser
/// reported a dead-end recovery (looking around, escaping, no route): the
/// forward-speed rule is relaxed there by design, so the verdict does not
/// count the forward speed within it or within kRecoverySettle after it.
struct TimeSpan {
  double begin = 0;
  double end = 0;
};
constexpr double kRecoverySettle = 2.0;  // s

FlightSummary analyse_flight(const std::vector<NavSample>& nav,
                             const std::vector<StatusSample>& status, const Limits& limits,
                             std::optional<double> start_gate, std::optional<double> finish_gate,
                             const std::vector<TimeSpan>& recovery = {});

/// One step of the RH optimiser that published a trajectory: when, and the
/// stamp of the map it planned on (SOLVER_STATS.map_utime), both in s of
/// the flight's clock.
struct PlanStep {
  double published = 0;
  double map = 0;
};

/// Scan-to-plan latency, s: for each map stamp (an OBSTACLE_GRID's, the
/// newest scan in it) taken while the optimiser was planning (a step
/// published at most `active_gap` before it), the time from the stamp to
/// the first step published on a map at least that new. A stamp that no
/// step planned on before a pause in planning longer than `active_gap` is
/// left out. `steps` in publication order.
std::vector<double> scan_to_plan_latencies(const std::vector<double>& map_stamps,
                                           const std::vector<PlanStep>& steps,
                                           double active_gap = 0.5);

}  // namespace ofn::report
