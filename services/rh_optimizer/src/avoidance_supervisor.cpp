#include "ofn/rh_optimizer/avoidance_supervisor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "ofn/rh_optimizer/step_problem.hpp"

namespace ofn::rh {
namespace {

using Publish = SupervisorDecision::Publish;

StatsStatus stats_status(StepMode mode) {
  switch (mode) {
    case StepMode::kSolved:
      return StatsStatus::kSolved;
    case StepMode::kKeptPrevious:
      return StatsStatus::kKeptPrevious;
    case StepMode::kBraking:
      break;
  }
  return StatsStatus::kBraking;
}

PlanMode plan_mode(StepMode mode) {
  switch (mode) {
    case StepMode::kSolved:
      return PlanMode::kAvoidance;
    case StepMode::kKeptPrevious:
      return PlanMode::kPrevious;
    case StepMode::kBraking:
      break;
  }
  return PlanMode::kBraking;
}

double distance_to_polyline(const std::vector<Vec3>& line, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  if (line.size() == 1) return (line[0] - p).norm();
  for (size_t i = 1; i < line.size(); ++i)
    best = std::min(best, distance_to_segment(p, line[i - 1], line[i]));
  return best;
}

LogLine info(std::string text) {
  return {LogLine::Level::kInfo, std::move(text)};
}
LogLine warn(std::string text) {
  return {LogLine::Level::kWarn, std::move(text)};
}

}  // namespace

double route_difference(const std::vector<Vec3>& a, const std::vector<Vec3>& b, const Vec3& from,
                        double horizon) {
  if (a.empty() || b.empty()) return std::numeric_limits<double>::infinity();
  double worst = 0;
  for (const auto& p : b) {
    if ((p - from).norm() > horizon) continue;
    worst = std::max(worst, distance_to_polyline(a, p));
  }
  return worst;
}

AvoidanceSupervisor::AvoidanceSupervisor(SupervisorSettings settings)
    : settings_(std::move(settings)),
      planner_(settings_.optimizer, settings_.fallback, settings_.commit),
      switch_(settings_.avoidance),
      recovery_(settings_.recovery),
      passages_(settings_.passages.max_passages),
      scan_supply_(settings_.scan_supply),
      tube_(settings_.tracking_tube) {}

void AvoidanceSupervisor::start_mission(int mission_id, std::vector<Waypoint> waypoints,
                                        const Limits& limits) {
  has_mission_ = true;
  mission_id_ = mission_id;
  waypoints_ = std::move(waypoints);
  limits_ = limits;
  legs_.clear();
  active_leg_ = -1;
  restart_planning();
  switch_.reset();
  passages_.clear();
}

std::vector<LogLine> AvoidanceSupervisor::route(const RouteInput& r,
                                                const std::optional<Vec3>& vehicle) {
  // What the planner says decides a dead end's recovery: a route along the
  // leg (also one only too sharp to fly), one that turns back, or none.
  std::vector<LogLine> log;
  route_kind_utime_ = r.utime;
  route_kind_ = r.kind;
  recovery_route_.clear();
  if (route_kind_ != RouteKind::kNoPath) recovery_route_ = r.points;
  // A route that is no guess (none, one that turns back) leaves the guess
  // in use as it is.
  if (!r.guess) return log;
  const Vec3 from = vehicle ? *vehicle : r.points.front();
  const double horizon = has_mission_ ? limits_.sensor_range : 60.0;
  // The planner re-publishes every second; only a different way round is a
  // new route (and a reason to drop the warm start).
  if (route_.empty() ||
      route_difference(route_, r.points, from, horizon) > settings_.route_change_distance) {
    route_changed_ = true;
    if (!route_.empty())
      log.push_back(info(fmt::format("new global route ({} points)", r.points.size())));
  }
  route_ = r.points;
  route_utime_ = r.utime;
  return log;
}

SupervisorDecision& AvoidanceSupervisor::with_stats(SupervisorDecision& d,
                                                    SupervisorDecision::Publish publish,
                                                    StatsStatus status, const std::string& message,
                                                    const std::string& state) const {
  d.publish = publish;
  d.state = state;
  d.status = status;
  d.message = recovery_message(recovery_.phase(), message);
  return d;
}

double AvoidanceSupervisor::pinch_clearance(const Limits& limits) const {
  // What the optimiser accepts as feasible: its clearance, less its
  // (normalised) feasibility tolerance. Dense seed 83 blocked a gap 1 cm
  // short of the clearance, which it had flown before, and lost its way.
  return (limits.clearance + settings_.optimizer.clearance_margin) *
         (1.0 - settings_.optimizer.feasibility_tolerance);
}

double AvoidanceSupervisor::tracking_widening(Utime now, std::vector<LogLine>* log) {
  const double widening = tube_.extra_clearance();
  if (std::abs(widening - logged_widening_) >= 0.25 ||
      (widening == 0.0) != (logged_widening_ == 0.0)) {
    log->push_back(info(fmt::format(
        "t={:.2f} s tracking tube: clearances widened by {:.2f} m (largest position error {:.2f} m "
        "over the last {:.0f} s)",
        to_seconds(now), widening, tube_.largest_error(), settings_.tracking_tube.window)));
    logged_widening_ = widening;
  }
  return widening;
}

bool AvoidanceSupervisor::check_route_for_pinch(Utime now, const Limits& limits,
                                                const GuidanceFrame& leg,
                                                const ClearanceQuery& clearance,
                                                SupervisorDecision* d) {
  if (!clearance) return false;
  // On the field the plans are made on, after the look: the shadows
  // behind what was seen (occlusion) it cleared are gone, those left are
  // what the optimiser will meet. (Checked when the vehicle got stuck,
  // before the look, a gap they closed then was open after it: dense seed
  // 68 lost its way so.)
  const double required = pinch_clearance(limits);
  std::optional<NarrowPassage> pinch =
      find_narrow_passage(clearance, recovery_route_, required, settings_.passages);
  const char* what = "the route passes a pinch";
  if (!pinch && !recovery_route_.empty()) {
    // An escape flies to the route's first corner and stops there; the
    // route's sections may leave room to pass a corner in a gap but none
    // to stop in it, and the escape stalled there look after look (dense
    // seed 162).
    const auto corner = escape_leg_end(recovery_route_, leg, settings_.recovery.capture_radius);
    if (corner && *corner > 0) {
      pinch = find_cramped_stop(clearance, recovery_route_[*corner], required, settings_.passages);
      what = "the escape would stop at a corner with no room";
    }
  }
  // One the planner knows already is not its doing (a zone round the
  // start, which routes may leave): the route is taken.
  if (!pinch || !passages_.add(*pinch)) return false;
  const double ground = settings_.optimizer.ground_altitude;
  d->log.push_back(warn(fmt::format(
      "t={:.2f} s {} with {:.2f} m of the {:.2f} m clearance: told to the global planner (no "
      "route within {:.1f} m of ({:.1f}, {:.1f}) m north/east, {:.1f} to {:.1f} m above the "
      "ground)",
      to_seconds(now), what, pinch->clearance, required, pinch->radius, pinch->centre.x(),
      pinch->centre.y(), -(pinch->centre.z() + pinch->half_height) - ground,
      -(pinch->centre.z() - pinch->half_height) - ground)));
  d->passages_changed = true;
  return true;
}

RecoveryDecision AvoidanceSupervisor::update_recovery(Utime now, const Leg& leg,
                                                      const Limits& limits, const NavInput& nav,
                                                      bool engaged, const ClearanceQuery& clearance,
                                                      const SeenQuery& seen,
                                                      SupervisorDecision* d) {
  RecoveryInput in;
  in.time = to_seconds(now);
  in.position = nav.position;
  in.velocity = nav.velocity;
  in.altitude = -nav.position.z() - settings_.optimizer.ground_altitude;
  in.max_vertical_speed = limits.max_vertical_speed;
  in.yaw = nav.yaw;
  in.engaged = engaged;
  in.moving_plan = last_step_moving_;
  in.route = route_kind_;
  in.route_time = route_kind_utime_ == INT64_MIN ? -1e300 : to_seconds(route_kind_utime_);
  in.route_points = &recovery_route_;
  in.leg = GuidanceFrame::from_leg(leg.from, leg.to);
  in.route_flyable = [&] { return !check_route_for_pinch(now, limits, in.leg, clearance, d); };
  in.way_seen = [&](const Vec3& from, const Vec3& to) {
    return way_seen(seen, from, to, settings_.commit.seen_resolution / 2);
  };
  RecoveryDecision decision = recovery_.update(in);
  if (decision.changed) {
    d->log.push_back(warn(fmt::format("t={:.2f} s recovery: {}: {}", in.time,
                                      to_string(decision.phase), decision.reason)));
    // Each phase plans afresh: an escape in its own frame, normal planning
    // from wherever the escape or the look left the vehicle.
    planner_.reset();
    route_changed_ = true;
    last_step_moving_ = false;
  }
  return decision;
}

void AvoidanceSupervisor::restart_planning() {
  planner_.reset();
  recovery_.reset();
  last_step_moving_ = false;
  last_trajectory_ = BsplineTrajectory();
  last_trajectory_kind_ = LastPlan::kMoving;
  stopping_at_target_ = false;
  stalled_ = false;
}

SupervisorDecision AvoidanceSupervisor::tick(const TickInput& in) {
  SupervisorDecision d;
  const Utime now = in.now;
  if (!has_mission_ || !in.nav) {
    d.state = "waiting for mission and nav";
    return d;
  }
  const NavInput& nav = *in.nav;
  if (now - nav.utime > to_utime(settings_.nav_max_age))
    return with_stats(d, Publish::kStats, StatsStatus::kNotRun, "nav stale", "nav stale");
  if (!legs_.has_plan()) legs_.set_plan(mission_id_, waypoints_, nav.position);
  const auto active = legs_.update(nav.position);
  if (!active) {
    d.state = "no leg";
    return d;
  }
  if (active->index != active_leg_) {
    // A new leg is a new guidance frame: the previous solution is no guess.
    active_leg_ = active->index;
    planner_.reset();
    recovery_.reset();
    route_changed_ = true;
  }
  if (!in.grid_utime || now - *in.grid_utime > to_utime(settings_.grid_max_age)) {
    // Blind: no decisions on a map that is not there. An engaged avoidance
    // keeps its last trajectory until the controller times it out.
    return with_stats(d, Publish::kStats, StatsStatus::kNotRun, "no fresh obstacle grid",
                      "no fresh obstacle grid");
  }
  // A map fed by a trickle of scans is as blind as none: no plans, and
  // guidance holds (PerceptionWatch); the controller flies the last plan's
  // stop.
  if (scan_supply_.starved(to_seconds(now))) {
    if (!scans_starved_)
      d.log.push_back(
          warn(fmt::format("map starved of scans at t={:.2f} s ({}): no plans until fed again",
                           to_seconds(now), scan_supply_.why())));
    scans_starved_ = true;
    return with_stats(d, Publish::kStats, StatsStatus::kNotRun,
                      "map starved of scans: " + scan_supply_.why(), "map starved of scans");
  }
  if (scans_starved_) {
    d.log.push_back(info(fmt::format("map fed again at t={:.2f} s ({:.0f} % of the scans arrive)",
                                     to_seconds(now), 100.0 * scan_supply_.share())));
    scans_starved_ = false;
  }
  return decide(d, now, nav, *active, in.map());
}

SupervisorDecision& AvoidanceSupervisor::decide(SupervisorDecision& d, Utime now,
                                                const NavInput& nav, const ActiveLeg& active,
                                                const MapView& map) {
  const Vec3& position = nav.position;
  const Vec3& velocity = nav.velocity;
  Limits limits = limits_;
  limits.clearance += tracking_widening(now, &d.log);
  const Leg leg{active.from, active.to};
  const ClearanceQuery& clearance = map.clearance;
  const double required = limits.clearance + settings_.avoidance.engage_margin;
  const NominalCheck nominal = check_nominal_path(clearance, leg, position, limits.sensor_range,
                                                  required, settings_.avoidance);
  const bool conflict = std::isfinite(nominal.conflict_distance);
  const bool was_engaged = switch_.engaged();
  const double t = to_seconds(now);
  const double stopping_speed = stopping_at_target_ ? velocity.norm() : 0.0;
  // Only while the plan stops there, so that the switch asks for rest
  // (stopping_speed): handed back at speed so near, guidance overshoots.
  const bool at_last_waypoint =
      stopping_at_target_ && active.final && (position - active.to).norm() <= active.capture_radius;
  const bool engaged = switch_.update(t, conflict, cross_track_distance(leg, position),
                                      stopping_speed, at_last_waypoint);
  const RecoveryDecision recovery =
      update_recovery(now, leg, limits, nav, engaged, clearance, map.seen, &d);
  if (!engaged) {
    Publish publish = Publish::kStats;
    if (was_engaged) {
      // NOMINAL tells the controller to resume waypoint guidance at once.
      publish = Publish::kNominal;
      restart_planning();
      d.log.push_back(
          info(fmt::format("avoidance hands back to waypoint guidance at t={:.2f} s ({})", t,
                           "nominal path clear, back on the leg")));
    } else if (++ticks_since_nominal_ >= static_cast<int64_t>(std::ceil(settings_.rate))) {
      // Once a second while guidance is clear: a controller left flying the
      // stop of a plan from an optimiser that has since died and restarted
      // learns that guidance may resume.
      publish = Publish::kNominal;
      ticks_since_nominal_ = 0;
    }
    with_stats(d, publish, StatsStatus::kNotRun, "nominal guidance: path clear",
               "nominal guidance");
    d.guidance_clear = true;
    return d;
  }
  if (!was_engaged)
    d.log.push_back(info(fmt::format(
        "avoidance engages at t={:.2f} s: nominal path clearance {:.1f} m < {:.1f} m, {:.1f} m "
        "ahead",
        t, nominal.least_clearance, required, nominal.conflict_distance)));

  StepInput in;
  // On the last plan while the vehicle is near it, else at the measured
  // state (start_state.hpp).
  const StartState start = choose_start_state(
      last_trajectory_, last_trajectory_kind_, to_seconds(now - last_trajectory_t0_),
      MeasuredState{position, velocity, nav.acceleration}, limits_.max_accel, settings_.start);
  FramingSettings framing;
  framing.clearance_margin = settings_.optimizer.clearance_margin;
  framing.pinch_clearance = pinch_clearance(limits);
  framing.max_shift = settings_.passages.max_shift;
  in.problem =
      leg_problem(leg, active.final, start, position, limits, clearance, *map.heightfield, framing);
  RhProblem& p = in.problem;
  stopping_at_target_ = p.stop_at_target;
  in.time = t;
  if (!route_.empty() && now - route_utime_ <= to_utime(settings_.path_max_age))
    in.global_path = route_;
  in.global_path_changed = route_changed_;
  route_changed_ = false;

  if (recovery.phase == RecoveryPhase::kLooking || recovery.phase == RecoveryPhase::kTurning ||
      recovery.phase == RecoveryPhase::kNoRoute) {
    // Hover where the stop from the state flown ends; while looking (or
    // turning to an escape leg), the controller turns the heading.
    const bool looking = recovery.phase != RecoveryPhase::kNoRoute;
    d.trajectory = planner_.braking_trajectory(p);
    d.t0 = to_utime(t);
    d.mode = !looking             ? PlanMode::kBraking
             : recovery.turn_left ? PlanMode::kLookAroundLeft
                                  : PlanMode::kLookAround;
    last_trajectory_ = d.trajectory;
    last_trajectory_kind_ = LastPlan::kStop;
    last_trajectory_t0_ = d.t0;
    last_step_moving_ = false;
    const std::string what = std::string("recovery: ") + to_string(recovery.phase);
    return with_stats(d, Publish::kHover,
                      looking ? StatsStatus::kLookingAround : StatsStatus::kNoRoute, what, what);
  }
  if (recovery.phase == RecoveryPhase::kEscaping) {
    // The leg of the escape: from where it began to where the route turns
    // forward again, along the route; the forward-speed rule of Eq. 8 is
    // relaxed (the route may bend back), the commit gate is not.
    frame_escape(&p, recovery.escape_from, recovery.escape_point, position, *map.heightfield,
                 framing);
    stopping_at_target_ = false;
    in.global_path = recovery.escape_route;
  }
  in.seen = map.seen;

  // A climb to look over what the scanner saw from below, straight up from
  // the hover the look left; the controller turns the heading on the way,
  // so the scanner looks all round at every altitude it passes.
  const bool climbing = recovery.phase == RecoveryPhase::kClimbing;
  const StepOutput out =
      climbing ? planner_.climb(in, -(settings_.optimizer.ground_altitude + recovery.climb_target))
               : planner_.step(in);
  ++steps_;
  // A plan that moves off, not a stop, a stall or a hover in place: the
  // recovery counts the vehicle stuck without one.
  last_step_moving_ = plan_moves_off(out, 2.0 * settings_.recovery.capture_radius);
  // Deferring leaves the vehicle to nominal guidance: only before this
  // engagement has published anything. Once a plan or a stop has been
  // flown, the controller holds to it (and to its stop) and a silence
  // would only leave it hovering.
  if (out.mode == StepMode::kBraking && last_trajectory_.empty() &&
      defer_first_brake(nominal.conflict_distance, velocity,
                        settings_.fallback.braking_accel_fraction * limits.max_accel,
                        settings_.defer_margin)) {
    with_stats(d, Publish::kStats, StatsStatus::kDeferred,
               "no avoidance trajectory yet (" + out.reason +
                   "); conflict still far, nominal guidance continues",
               "avoidance deferred: no trajectory yet");
    d.report = out.report;
    d.guidance_clear = true;
    return d;
  }
  d.t0 = to_utime(out.start_time);
  d.mode = climbing && out.mode == StepMode::kSolved ? PlanMode::kLookAround : plan_mode(out.mode);
  d.trajectory = out.trajectory;
  d.frame = p.frame;
  last_trajectory_ = out.trajectory;
  last_trajectory_kind_ = out.mode == StepMode::kBraking ? LastPlan::kStop : LastPlan::kMoving;
  last_trajectory_t0_ = d.t0;
  std::string message = recovery_message(recovery.phase, to_string(out.mode));
  if (!out.reason.empty()) message += ": " + out.reason;
  if (out.mode == StepMode::kSolved && out.refused > 0)
    message += (out.reason.empty() ? ": " : "; ") + std::string("the commit gate refused ") +
               std::to_string(out.refused) + " other plan(s) (" + out.refusal + ")";
  if (out.mode != StepMode::kSolved) {
    // One line per streak of like steps (the caller's WarningStreak: the
    // first in full, then a summary); every step's message still goes out
    // in SOLVER_STATS.
    d.warning = StepWarning{recovery_message(recovery.phase, to_string(out.mode)),
                            fmt::format("t={:.2f} s {} ({} solves, worst violation {:.3g})", t,
                                        message, out.solves, out.report.max_violation),
                            out.report.max_violation};
  } else if (out.refused > 0) {
    d.log.push_back(info(fmt::format("t={:.2f} s {}", t, message)));
  } else if (out.stalled != stalled_) {
    d.log.push_back(
        info(fmt::format("t={:.2f} s {}", t, out.stalled ? message : "no longer stalled")));
  }
  stalled_ = out.stalled;
  with_stats(d, Publish::kStep, stats_status(out.mode), message,
             std::string("avoiding: ") + to_string(out.mode));
  d.report = out.report;
  return d;
}

}  // namespace ofn::rh
