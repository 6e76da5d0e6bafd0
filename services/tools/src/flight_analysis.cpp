#include "ofn/tools/flight_analysis.hpp"

#include <cmath>
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

FlightSummary analyse_flight(const std::vector<NavSample>& nav,
                             const std::vector<StatusSample>& status, const Limits& limits,
                             std::optional<double> start_gate, std::optional<double> finish_gate) {
  FlightSummary s;
  if (!nav.empty()) s.duration = nav.back().t - nav.front().t;
  for (const auto& n : nav) {
    s.max_speed = std::max(s.max_speed, n.velocity.norm());
    s.max_vertical_speed = std::max(s.max_vertical_speed, std::abs(n.velocity.z()));
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
      if (n.t < *s.gate_start_time || n.t > *s.gate_finish_time) continue;
      s.min_forward_speed = first ? n.velocity.x() : std::min(s.min_forward_speed, n.velocity.x());
      first = false;
    }
  }

  double sum_sq = 0;
  size_t count = 0;
  for (const auto& st : status) {
    if (st.mode == control_status_t::DONE) s.reached_last_waypoint = true;
    // Only the part of the flight where a plan is flown counts.
    if (st.mode != control_status_t::WAYPOINT && st.mode != control_status_t::TRAJECTORY) continue;
    s.max_commanded_accel = std::max(s.max_commanded_accel, st.ref_acceleration.norm());
    s.max_pseudo_control = std::max(s.max_pseudo_control, st.commanded_accel.norm());
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

Verdict judge_flight(const FlightSummary& s, const Limits& limits,
                     std::optional<double> min_clearance, bool has_finish_gate) {
  Verdict v;
  const auto fail = [&v](const std::string& what, double value, double bound) {
    std::ostringstream line;
    line.precision(3);
    line << what << ": " << value << " against " << bound;
    v.failures.push_back(line.str());
  };
  const double over = 1.0 + kLimitTolerance;
  if (has_finish_gate && !s.crossed_finish) v.failures.push_back("missed the finish gate");
  if (min_clearance && *min_clearance < kClearanceFailShare * limits.clearance)
    fail("clearance (m) below 0.8 R_s", *min_clearance, kClearanceFailShare * limits.clearance);
  if (s.max_speed > over * limits.max_speed)
    fail("speed (m/s) over the limit + 2 %", s.max_speed, over * limits.max_speed);
  if (s.max_vertical_speed > over * limits.max_vertical_speed)
    fail("vertical speed (m/s) over the limit + 2 %", s.max_vertical_speed,
         over * limits.max_vertical_speed);
  if (s.max_commanded_accel_fraction > over)
    fail("commanded acceleration (share of the limit) over 1.02", s.max_commanded_accel_fraction,
         over);
  if (s.min_forward_speed < -kLimitTolerance * limits.max_speed)
    fail("forward speed (m/s) below -2 % of the speed limit", s.min_forward_speed,
         -kLimitTolerance * limits.max_speed);
  v.success = v.failures.empty();
  return v;
}

}  // namespace ofn::report
