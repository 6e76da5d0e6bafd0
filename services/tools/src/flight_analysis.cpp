#include "ofn/tools/flight_analysis.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <sstream>

#include "ofn/control_status_t.hpp"

namespace ofn::report {

std::optional<double> crossing_time(const std::vector<NavSample>& nav, double x) {
  for (size_t i = 1; i < nav.size(); ++i) {
    const double a = nav[i - 1].position.x(), b = nav[i].position.x();
    if (a < x && b >= x) {
      const double f = (x - a) / (b - a);
      return nav[i - 1].t + f * (nav[i].t - nav[i - 1].t);
    }
  }
  return std::nullopt;  // never crossed, or started past the line
}

bool flies_a_plan(int mode) {
  // A deny list rather than WAYPOINT and TRAJECTORY alone: a mode added
  // later in which the controller flies (a planned stop, say) is judged
  // like the others instead of passing unseen.
  return mode != control_status_t::HOLD && mode != control_status_t::NAV_STALE &&
         mode != control_status_t::DONE;
}

FlightSummary analyse_flight(const std::vector<NavSample>& nav,
                             const std::vector<StatusSample>& status, const Limits& limits,
                             std::optional<double> start_gate, std::optional<double> finish_gate,
                             const std::vector<TimeSpan>& recovery) {
  FlightSummary s;
  for (const TimeSpan& span : recovery) s.recovery_time += std::max(0.0, span.end - span.begin);
  const auto recovering = [&recovery](double t) {
    for (const TimeSpan& span : recovery)
      if (t >= span.begin && t <= span.end + kRecoverySettle) return true;
    return false;
  };
  if (!nav.empty()) s.duration = nav.back().t - nav.front().t;
  for (const auto& n : nav) {
    s.max_speed = std::max(s.max_speed, n.velocity.norm());
    s.max_vertical_speed = std::max(s.max_vertical_speed, std::abs(n.velocity.z()));
  }
  if (!nav.empty() && s.duration >= kHoverWindow) {
    double final_max = 0;
    for (auto it = nav.rbegin(); it != nav.rend() && it->t >= nav.back().t - kHoverWindow; ++it)
      final_max = std::max(final_max, it->velocity.norm());
    s.final_max_speed = final_max;
  }
  if (start_gate) s.gate_start_time = crossing_time(nav, *start_gate);
  if (finish_gate) {
    s.gate_finish_time = crossing_time(nav, *finish_gate);
    s.crossed_finish = s.gate_finish_time.has_value();
  }
  if (s.gate_start_time && s.gate_finish_time) {
    s.gate_to_gate = *s.gate_finish_time - *s.gate_start_time;
    bool first = true;
    for (const auto& n : nav) {
      if (n.t < *s.gate_start_time || n.t > *s.gate_finish_time || recovering(n.t)) continue;
      s.min_forward_speed = first ? n.velocity.x() : std::min(s.min_forward_speed, n.velocity.x());
      first = false;
    }
  }

  double sum_sq = 0;
  size_t count = 0;
  const StatusSample* previous = nullptr;  // the last sample, if it flew the plan
  for (const auto& st : status) {
    if (st.mode == control_status_t::DONE) s.reached_last_waypoint = true;
    // Only the part of the flight where a plan is flown counts: before the
    // controller engages, the reference and the command are a hold's.
    if (!flies_a_plan(st.mode)) {
      previous = nullptr;
      continue;
    }
    s.max_commanded_accel = std::max(s.max_commanded_accel, st.ref_acceleration.norm());
    s.max_pseudo_control = std::max(s.max_pseudo_control, st.commanded_accel.norm());
    s.max_pseudo_control_horizontal =
        std::max(s.max_pseudo_control_horizontal, st.commanded_accel.head<2>().norm());
    s.max_pseudo_control_vertical =
        std::max(s.max_pseudo_control_vertical, std::abs(st.commanded_accel.z()));
    if (previous) {
      const double dt = st.t - previous->t;
      const double position_jump = (st.ref_position - previous->ref_position -
                                    0.5 * dt * (st.ref_velocity + previous->ref_velocity))
                                       .norm();
      const double velocity_jump = (st.ref_velocity - previous->ref_velocity -
                                    0.5 * dt * (st.ref_acceleration + previous->ref_acceleration))
                                       .norm();
      // Onto the vehicle: the controller took over from where it is, so
      // nothing is left to chase.
      const bool onto_vehicle = st.position_error.norm() <= kMaxReferenceJump;
      if (position_jump > kMaxReferenceJump && onto_vehicle) {
        ++s.reference_resyncs;
      } else if (position_jump > s.max_ref_position_jump) {
        s.max_ref_position_jump = position_jump;
        s.max_ref_position_jump_t = st.t;
      }
      s.max_ref_velocity_jump = std::max(s.max_ref_velocity_jump, velocity_jump);
    }
    previous = &st;
    const double e = st.position_error.norm();
    s.tracking_max = std::max(s.tracking_max, e);
    sum_sq += e * e;
    ++count;
  }
  if (count) s.tracking_rms = std::sqrt(sum_sq / static_cast<double>(count));
  if (limits.max_accel > 0)
    s.max_commanded_accel_fraction = s.max_commanded_accel / limits.max_accel;
  return s;
}

const char* to_string(Outcome outcome) {
  switch (outcome) {
    case Outcome::kSuccess:
      return "success";
    case Outcome::kSafeStop:
      return "safe_stop";
    case Outcome::kFailure:
      return "failure";
  }
  return "failure";
}

ControlSaturation control_saturation(const std::vector<std::array<double, 4>>& commands,
                                     const ControlStops& stops) {
  ControlSaturation out;
  out.samples = commands.size();
  if (commands.empty()) return out;
  std::array<size_t, 4> at_stop{};
  size_t cyclic = 0, any = 0;
  for (const auto& command : commands) {
    std::array<bool, 4> at{};
    for (size_t i = 0; i < 4; ++i) {
      const double band = kStopBand * (stops.max[i] - stops.min[i]);
      at[i] = std::isfinite(command[i]) &&
              (command[i] <= stops.min[i] + band || command[i] >= stops.max[i] - band);
      at_stop[i] += at[i];
    }
    cyclic += at[1] || at[2];
    any += at[0] || at[1] || at[2] || at[3];
  }
  const double n = static_cast<double>(commands.size());
  for (size_t i = 0; i < 4; ++i) out.share[i] = static_cast<double>(at_stop[i]) / n;
  out.cyclic_share = static_cast<double>(cyclic) / n;
  out.any_share = static_cast<double>(any) / n;
  return out;
}

Verdict judge_flight(const FlightSummary& s, const Limits& limits,
                     const PseudoControlBound& pseudo_control_bound,
                     std::optional<double> min_clearance, bool has_finish_gate,
                     const DisplayUnit& unit) {
  Verdict v;
  // The figures are SI; the lines give lengths in the display unit.
  const double per_metre = 1.0 / unit.metres_per_unit;
  const auto fail = [&v](const std::string& what, double value, double bound) {
    std::ostringstream line;
    line.precision(3);
    line << what << ": " << value << " against " << bound;
    v.failures.push_back(line.str());
  };
  const std::string& u = unit.name;
  const double over = 1.0 + kLimitTolerance;
  if (min_clearance && *min_clearance < kClearanceFailShare * limits.clearance)
    fail("clearance (" + u + ") below 0.8 R_s", *min_clearance * per_metre,
         kClearanceFailShare * limits.clearance * per_metre);
  if (s.max_speed > over * limits.max_speed)
    fail("speed (" + u + "/s) over the limit + 2 %", s.max_speed * per_metre,
         over * limits.max_speed * per_metre);
  if (s.max_vertical_speed > over * limits.max_vertical_speed)
    fail("vertical speed (" + u + "/s) over the limit + 2 %", s.max_vertical_speed * per_metre,
         over * limits.max_vertical_speed * per_metre);
  if (s.max_commanded_accel_fraction > over)
    fail("reference acceleration (share of the limit) over 1.02", s.max_commanded_accel_fraction,
         over);
  if (s.min_forward_speed < -kLimitTolerance * limits.max_speed)
    fail("forward speed (" + u + "/s) below -2 % of the speed limit",
         s.min_forward_speed * per_metre, -kLimitTolerance * limits.max_speed * per_metre);
  if (s.max_pseudo_control_horizontal > over * pseudo_control_bound.horizontal)
    fail("controller command out of its bound: horizontal pseudo-control (" + u +
             "/s^2) over the bound + 2 %",
         s.max_pseudo_control_horizontal * per_metre,
         over * pseudo_control_bound.horizontal * per_metre);
  if (s.max_pseudo_control_vertical > over * pseudo_control_bound.vertical)
    fail("controller command out of its bound: vertical pseudo-control (" + u +
             "/s^2) over the bound + 2 %",
         s.max_pseudo_control_vertical * per_metre,
         over * pseudo_control_bound.vertical * per_metre);
  if (s.max_ref_position_jump > kMaxReferenceJump) {
    std::ostringstream what;
    what.precision(3);
    what << "reference jump (" << u
         << ") between consecutive samples at t = " << s.max_ref_position_jump_t.value_or(0.0)
         << " s";
    fail(what.str(), s.max_ref_position_jump * per_metre, kMaxReferenceJump * per_metre);
  }

  const bool goal_reached = has_finish_gate ? s.crossed_finish : s.reached_last_waypoint;
  const bool ends_at_hover = s.final_max_speed && *s.final_max_speed < kHoverSpeed;
  if (!goal_reached && !(v.failures.empty() && ends_at_hover)) {
    std::ostringstream line;
    line.precision(3);
    line << (has_finish_gate ? "missed the finish gate" : "did not reach the last waypoint");
    if (!ends_at_hover) {
      line << " and did not end at a hover";
      if (s.final_max_speed)
        line << " (speed up to " << *s.final_max_speed * per_metre << " " << u
             << "/s over the last " << kHoverWindow << " s)";
    }
    v.failures.push_back(line.str());
  }
  if (!v.failures.empty())
    v.outcome = Outcome::kFailure;
  else
    v.outcome = goal_reached ? Outcome::kSuccess : Outcome::kSafeStop;
  v.success = v.outcome == Outcome::kSuccess;
  return v;
}

std::vector<double> scan_to_plan_latencies(const std::vector<double>& map_stamps,
                                           const std::vector<PlanStep>& steps, double active_gap) {
  std::vector<double> latencies;
  for (const double stamp : map_stamps) {
    // The first step published at or after the stamp; the one before it
    // says whether the optimiser was planning then.
    const auto after =
        std::lower_bound(steps.begin(), steps.end(), stamp,
                         [](const PlanStep& step, double t) { return step.published < t; });
    if (after == steps.begin() || stamp - std::prev(after)->published > active_gap) continue;
    // Planning must go on until then: after a pause (avoidance handed
    // back) the next step is not this scan's answer.
    double last = std::prev(after)->published;
    for (auto it = after; it != steps.end() && it->published - last <= active_gap; ++it) {
      if (it->map >= stamp) {
        latencies.push_back(it->published - stamp);
        break;
      }
      last = it->published;
    }
  }
  return latencies;
}

std::optional<Clearance> least_clearance(const std::vector<NavSample>& nav,
                                         const world::World& truth) {
  std::optional<Clearance> least;
  for (const auto& n : nav) {
    const double to_obstacle = truth.distance_to_obstacles(n.position, n.t);
    const double to_ground = truth.distance_to_ground(n.position);
    const double d = std::min(to_obstacle, to_ground);
    if (!least || d < least->distance) least = Clearance{d, n.t, to_ground <= to_obstacle};
  }
  return least;
}

}  // namespace ofn::report
