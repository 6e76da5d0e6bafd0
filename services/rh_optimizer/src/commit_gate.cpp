#include "ofn/rh_optimizer/commit_gate.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "ofn/common/envelope.hpp"

namespace ofn::rh {
namespace {

constexpr double kClearanceSlack = 0.02;  // m a start already inside R_s may lose to rounding
constexpr double kCellEpsilon = 1e-6;     // m: a search radius that finds only the point's own cell

std::string describe(const char* what, double value, double bound, double t) {
  std::ostringstream s;
  s.precision(3);
  s << what << " " << value << " against " << bound << " at t=" << t << " s";
  return s.str();
}

}  // namespace

CommitGate::CommitGate(CommitSettings settings) : settings_(settings) {
  const CommitSettings& s = settings_;
  if (!(s.commit_time >= 0) || !(s.instant_spacing > 0) || !(s.stop_point_spacing > 0) ||
      !(s.braking_accel_fraction > 0) || !(s.unseen_clearance_fraction >= 0) ||
      !(s.stop_clearance_fraction >= 0) || !(s.seen_resolution > 0) ||
      !(s.envelope_sample_spacing > 0) || !(s.limit_tolerance >= 0))
    throw std::invalid_argument("CommitGate: settings out of range");
}

StopProfile CommitGate::stop_from_state(const Vec3& position, const Vec3& velocity,
                                        const Vec3& acceleration, const Limits& limits) const {
  return stop_from(position, velocity, acceleration,
                   settings_.braking_accel_fraction * limits.max_accel);
}

double CommitGate::unseen_distance(const SeenQuery& seen, const Vec3& point, double radius) const {
  if (!seen || radius <= 0) return radius;
  const double res = settings_.seen_resolution;
  const int reach = static_cast<int>(std::ceil(radius / res)) + 1;
  const double north = point.x(), east = point.y();
  const double row0 = std::floor(north / res), col0 = std::floor(east / res);
  double best = radius;
  for (int dr = -reach; dr <= reach; ++dr)
    for (int dc = -reach; dc <= reach; ++dc) {
      // Distance from the point to the cell's square (0 inside it).
      const double lo_n = (row0 + dr) * res, lo_e = (col0 + dc) * res;
      const double dn = std::max({lo_n - north, 0.0, north - (lo_n + res)});
      const double de = std::max({lo_e - east, 0.0, east - (lo_e + res)});
      const double d = std::hypot(dn, de);
      if (d >= best) continue;
      if (!seen(lo_n + 0.5 * res, lo_e + 0.5 * res)) best = d;
    }
  return best;
}

CommitCheck CommitGate::check(const BsplineTrajectory& plan, double elapsed,
                              const FlownState& flown, const Limits& limits,
                              const SafetyMap& map) const {
  const CommitSettings& s = settings_;
  CommitCheck out;
  auto refuse = [&](const std::string& why) {
    out.committed = false;
    out.reason = why;
    return out;
  };
  if (plan.empty() || !std::isfinite(plan.duration()) || !std::isfinite(elapsed))
    return refuse("no finite plan");

  // 1. Continuity with what the controller flies now.
  const double dp = (plan.position(elapsed) - flown.position).norm();
  const double dv = (plan.velocity(elapsed) - flown.velocity).norm();
  const double da = (plan.acceleration(elapsed) - flown.acceleration).norm();
  if (!(dp <= s.position_tolerance))
    return refuse(describe("start position jump (m)", dp, s.position_tolerance, elapsed));
  if (!(dv <= s.velocity_tolerance))
    return refuse(describe("start velocity jump (m/s)", dv, s.velocity_tolerance, elapsed));
  if (!(da <= s.acceleration_tolerance))
    return refuse(
        describe("start acceleration jump (m/s^2)", da, s.acceleration_tolerance, elapsed));

  // 2. The envelope, sampled densely over the rest of the plan.
  const double over = 1.0 + s.limit_tolerance;
  const int envelope_samples = std::max(
      2, static_cast<int>(std::ceil((plan.duration() - elapsed) / s.envelope_sample_spacing)));
  for (int k = 0; k <= envelope_samples; ++k) {
    const double t = elapsed + std::max(0.0, plan.duration() - elapsed) * k / envelope_samples;
    const EnvelopeShares shares = envelope_shares(plan.velocity(t), plan.acceleration(t), limits);
    const double speed_share = shares.speed;
    const double climb_share = shares.vertical_speed;
    const double accel_share = shares.acceleration;
    out.worst_envelope_share = std::max(out.worst_envelope_share, shares.worst());
    if (!(speed_share <= over))
      return refuse(describe("speed share of the limit", speed_share, over, t));
    if (!(climb_share <= over))
      return refuse(describe("vertical speed share of the limit", climb_share, over, t));
    if (!(accel_share <= over))
      return refuse(describe("acceleration share of the limit", accel_share, over, t));
  }

  // 3. The stop from every committed instant, in space seen free.
  const double unseen_rule = s.unseen_clearance_fraction * limits.clearance;
  const double clearance_rule = s.stop_clearance_fraction * limits.clearance;
  double start_clearance = 1e9;
  if (map.clearance) start_clearance = map.clearance(flown.position).distance;
  const double clearance_bound =
      start_clearance >= clearance_rule ? clearance_rule : start_clearance - kClearanceSlack;
  // Distances to unseen cells come in steps of the cells: a start already
  // nearer than the rule may lose half a cell to the steps.
  const double start_unseen =
      unseen_distance(map.seen, flown.position, std::max(unseen_rule, kCellEpsilon));
  const bool start_seen = start_unseen > 0;
  const double unseen_bound = start_unseen >= unseen_rule
                                  ? unseen_rule
                                  : std::max(0.0, start_unseen - 0.5 * s.seen_resolution);
  const double start_altitude = -flown.position.z() - s.ground_altitude;
  const double altitude_bound = std::min(s.min_altitude, start_altitude - kClearanceSlack);

  const int instants = std::max(1, static_cast<int>(std::ceil(s.commit_time / s.instant_spacing)));
  for (int k = 0; k <= instants; ++k) {
    const double t = elapsed + s.commit_time * k / instants;
    const StopProfile stop =
        stop_from_state(plan.position(t), plan.velocity(t), plan.acceleration(t), limits);
    const int points = 1 + static_cast<int>(std::ceil(stop.distance() / s.stop_point_spacing));
    ++out.stops_checked;
    for (int i = 0; i <= points; ++i) {
      // Points equally spaced in distance along the straight stop.
      const double f = static_cast<double>(i) / points;
      const Vec3 p = stop.start + (stop.stop_point() - stop.start) * f;
      if (map.clearance) {
        const double c = map.clearance(p).distance;
        out.least_stop_clearance = std::min(out.least_stop_clearance, c);
        if (!(c >= clearance_bound))
          return refuse(describe("stop clearance (m)", c, clearance_bound, t));
      }
      const double altitude = -p.z() - s.ground_altitude;
      if (!(altitude >= altitude_bound))
        return refuse(describe("stop altitude (m)", altitude, altitude_bound, t));
      // Every point of the stop lies in a seen cell, and unseen_bound from
      // the nearest unseen one, unless the start itself is unseen.
      if (map.seen && start_seen) {
        const double u = unseen_distance(map.seen, p, std::max(unseen_bound, kCellEpsilon));
        out.least_unseen_distance = std::min(out.least_unseen_distance, u);
        // The stop's first point is the plan's, within position_tolerance of
        // the start the bound was measured at.
        if (!(u > 0)) {
          std::ostringstream why;
          why.precision(4);
          why << "the stop from t=" << t << " s enters a cell no beam has crossed, at (" << p.x()
              << ", " << p.y() << ") m";
          return refuse(why.str());
        }
        if (!(u >= unseen_bound - s.position_tolerance))
          return refuse(describe("stop distance to unseen space (m)", u, unseen_bound, t));
      }
    }
  }
  out.committed = true;
  return out;
}

bool way_seen(const SeenQuery& seen, const Vec3& from, const Vec3& to, double spacing) {
  if (!seen || !from.allFinite() || !to.allFinite() || !(spacing > 0)) return false;
  const double length = (to - from).head<2>().norm();
  const int steps = std::max(1, static_cast<int>(std::ceil(length / spacing)));
  for (int k = 0; k <= steps; ++k) {
    const Vec3 p = from + (to - from) * (static_cast<double>(k) / steps);
    if (!seen(p.x(), p.y())) return false;
  }
  return true;
}

}  // namespace ofn::rh
