#include "ofn/rh_optimizer/avoidance_switch.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "ofn/common/braking.hpp"

namespace ofn::rh {

bool defer_first_brake(double conflict_distance, const Vec3& velocity, double deceleration,
                       double margin) {
  return conflict_distance > stop_from(Vec3::Zero(), velocity, deceleration).distance() + margin;
}

double cross_track_distance(const Leg& leg, const Vec3& position) {
  const Vec3 d = leg.to - leg.from;
  const double length = d.norm();
  if (length < 1e-9) return (position - leg.from).norm();
  const Vec3 u = d / length;
  const Vec3 r = position - leg.from;
  return (r - r.dot(u) * u).norm();
}

NominalCheck check_nominal_path(const ClearanceQuery& clearance, const Leg& leg,
                                const Vec3& position, double lookahead, double required,
                                const SwitchSettings& s) {
  NominalCheck out;
  out.least_clearance = std::numeric_limits<double>::infinity();
  out.conflict_distance = std::numeric_limits<double>::infinity();
  if (!clearance) return out;
  const Vec3 d = leg.to - leg.from;
  const double length = d.norm();
  const Vec3 u = length > 1e-9 ? Vec3(d / length) : Vec3::UnitX();
  const double along = std::clamp((position - leg.from).dot(u), 0.0, length);
  const double end = std::min(length, along + lookahead);
  const double rejoin = std::min(end, along + kGuidanceRejoinDistance);
  const double step = std::max(0.1, s.check_spacing);
  auto check = [&](const Vec3& p, double travelled) {
    const double c = clearance(p).distance;
    out.least_clearance = std::min(out.least_clearance, c);
    if (c < required && !std::isfinite(out.conflict_distance)) out.conflict_distance = travelled;
  };
  // Rejoin segment: from the vehicle to the leg point `rejoin` along.
  const Vec3 rejoin_point = leg.from + rejoin * u;
  const double rejoin_length = (rejoin_point - position).norm();
  const int n_rejoin = std::max(1, static_cast<int>(std::ceil(rejoin_length / step)));
  for (int i = 0; i <= n_rejoin; ++i) {
    const double f = static_cast<double>(i) / n_rejoin;
    check(position + (rejoin_point - position) * f, f * rejoin_length);
  }
  // Then along the leg.
  for (double a = rejoin + step; a < end; a += step)
    check(leg.from + a * u, rejoin_length + a - rejoin);
  if (end > rejoin) check(leg.from + end * u, rejoin_length + end - rejoin);
  return out;
}

double terminal_x(const GuidanceFrame& frame, const mapping::Heightfield& grid,
                  const Vec3& position, double sensor_range, double beyond, double x_max,
                  double min_horizon) {
  const double x0 = frame.to_guidance(position).x();
  double farthest = -std::numeric_limits<double>::infinity();
  const double range2 = sensor_range * sensor_range;
  for (int r = 0; r < grid.rows; ++r) {
    const double north = grid.cell_centre_north(r);
    const double dn = north - position.x();
    if (dn * dn > range2) continue;
    for (int c = 0; c < grid.cols; ++c) {
      if (!(grid.at(r, c) > 0.0f)) continue;
      const double east = grid.cell_centre_east(c);
      const double de = east - position.y();
      if (dn * dn + de * de > range2) continue;
      const double x = frame.to_guidance(Vec3(north, east, position.z())).x();
      if (x > x0) farthest = std::max(farthest, x);
    }
  }
  double xf = x0 + sensor_range;
  if (std::isfinite(farthest)) xf = std::min(xf, farthest + beyond);
  xf = std::max(xf, x0 + min_horizon);
  return std::min(xf, x_max);
}

bool AvoidanceSwitch::update(double time, bool conflict, double cross_track, double stopping_speed,
                             bool at_last_waypoint) {
  if (conflict) {
    engaged_ = true;
    clear_since_ = -1;
    return engaged_;
  }
  if (!engaged_) return false;
  if (clear_since_ < 0) clear_since_ = time;
  if (time - clear_since_ >= settings_.handback_hold &&
      (cross_track <= settings_.handback_distance || at_last_waypoint) &&
      stopping_speed <= settings_.handback_stop_speed)
    reset();
  return engaged_;
}

}  // namespace ofn::rh
