#include "ofn/rh_optimizer/dead_end_recovery.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace ofn::rh {

const char* to_string(RecoveryPhase phase) {
  switch (phase) {
    case RecoveryPhase::kIdle:
      return "idle";
    case RecoveryPhase::kLooking:
      return "looking around";
    case RecoveryPhase::kTurning:
      return "turning to the way on";
    case RecoveryPhase::kEscaping:
      return "escaping";
    case RecoveryPhase::kClimbing:
      return "climbing to look";
    case RecoveryPhase::kNoRoute:
      return "no route";
  }
  return "?";
}

std::string recovery_message(RecoveryPhase phase, const std::string& message) {
  const char* mark = phase == RecoveryPhase::kEscaping   ? "escaping: "
                     : phase == RecoveryPhase::kClimbing ? "climbing: "
                                                         : nullptr;
  if (!mark || message.rfind(mark, 0) == 0) return message;
  return mark + message;
}

std::optional<size_t> escape_leg_end(const std::vector<Vec3>& route, const GuidanceFrame& leg,
                                     double min_length, double corner_angle) {
  const auto end = forward_from(route, leg);
  if (!end) return std::nullopt;
  const double cos_corner = std::cos(corner_angle);
  for (size_t k = 1; k < *end; ++k) {
    if ((route[k] - route.front()).norm() <= min_length) continue;
    const Vec3 in = route[k] - route[k - 1], out = route[k + 1] - route[k];
    if (in.norm() < 1e-6 || out.norm() < 1e-6) continue;
    if (in.normalized().dot(out.normalized()) < cos_corner) return k;
  }
  return end;
}

std::optional<size_t> forward_from(const std::vector<Vec3>& route, const GuidanceFrame& leg,
                                   double min_cosine) {
  if (route.size() < 2) return std::nullopt;
  size_t k = route.size() - 1;
  while (k > 0) {
    const Vec3 step = route[k] - route[k - 1];
    const double advance = leg.world_from_guidance.col(0).dot(step);
    if (!(advance > 0 && advance >= min_cosine * step.norm())) break;
    --k;
  }
  return k;
}

void DeadEndRecovery::reset() {
  decision_ = RecoveryDecision{};
  stuck_since_.reset();
  look_end_.reset();
  turned_ = 0;
  attempts_ = 0;
  narrow_route_time_ = -1e300;
}

void DeadEndRecovery::enter(RecoveryPhase phase, std::string reason) {
  decision_.phase = phase;
  decision_.changed = true;
  decision_.reason = std::move(reason);
  if (phase != RecoveryPhase::kEscaping &&
      !(phase == RecoveryPhase::kTurning && after_turn_ == RecoveryPhase::kEscaping))
    decision_.escape_route.clear();
  stuck_since_.reset();
  near_spot_.reset();
}

void DeadEndRecovery::begin_turn(const RecoveryInput& in) {
  turned_ = 0;
  last_yaw_ = in.yaw;
  look_start_ = in.time;
  look_end_.reset();
  facing_since_.reset();
  decision_.turn_left = false;
}

void DeadEndRecovery::face(double yaw, const RecoveryInput& in) {
  face_yaw_ = yaw;
  decision_.turn_left = wrap_angle(yaw - in.yaw) < 0.0;  // the shorter way round
}

bool DeadEndRecovery::turned_through(const RecoveryInput& in) {
  turned_ += wrap_angle(in.yaw - last_yaw_);
  last_yaw_ = in.yaw;
  return std::abs(turned_) >= settings_.look_turn ||
         in.time - look_start_ >= settings_.look_timeout;
}

DeadEndRecovery::Stuck DeadEndRecovery::stuck(const RecoveryInput& in) {
  if (!near_spot_ || !((in.position - *near_spot_).norm() <= settings_.progress_radius)) {
    near_spot_ = in.position;
    near_since_ = in.time;
  }
  if (in.time - near_since_ >= settings_.progress_time) return Stuck::kNoProgress;
  if (in.moving_plan || !(in.velocity.norm() < settings_.hover_speed)) {
    stuck_since_.reset();
    return Stuck::kNo;
  }
  if (!stuck_since_) stuck_since_ = in.time;
  return in.time - *stuck_since_ >= settings_.stuck_time ? Stuck::kHovering : Stuck::kNo;
}

bool DeadEndRecovery::take_route(const RecoveryInput& in) {
  if (in.route == RouteKind::kNone || in.route == RouteKind::kNoPath) return false;
  // Any route that does not head along the leg from here (one that turns
  // back, or goes sideways round a wall first) is flown as an escape: the
  // forward-only optimiser would take the shorter way straight on, back
  // into the dead end.
  const std::vector<Vec3> none;
  const std::vector<Vec3>& route = in.route_points ? *in.route_points : none;
  const auto k = escape_leg_end(route, in.leg, settings_.capture_radius);
  begin_turn(in);
  if (!k || (route[*k] - in.position).norm() <= settings_.capture_radius) {
    // Normal planning, once the scanner looks along the leg: a vehicle left
    // facing the way it came sees nothing ahead, and the commit gate lets
    // no plan into space no beam has crossed.
    const Vec3 x = in.leg.world_from_guidance.col(0);
    face(std::atan2(x.y(), x.x()), in);
    after_turn_ = RecoveryPhase::kIdle;
    enter(RecoveryPhase::kTurning,
          "the route heads along the leg from here: turning to it, then normal planning");
    return true;
  }
  const Vec3 point = route[*k];
  decision_.escape_from = in.position;
  decision_.escape_point = point;
  decision_.escape_route.assign(route.begin(), route.begin() + static_cast<std::ptrdiff_t>(*k) + 1);
  face(std::atan2(point.y() - in.position.y(), point.x() - in.position.x()), in);
  after_turn_ = RecoveryPhase::kEscaping;
  std::ostringstream why;
  why << "the route does not head along the leg from here: escaping along it, next to ("
      << point.x() << ", " << point.y() << ", " << point.z() << ") m, "
      << (point - in.position).norm() << " m away";
  // The turn to face the leg is for the scanner: the way it goes into
  // counts as obstacle until a beam has crossed it. A way already seen
  // (all round after a look) needs no turn; the controller's heading turns
  // towards the plan as it flies. Only from a hover: a leg is flown from
  // rest to rest, and the turn's hover is what stops a climb or a leg.
  if (settings_.skip_turn_when_seen && in.way_seen && in.velocity.norm() < settings_.hover_speed &&
      in.way_seen(in.position, point)) {
    why << "; its way is seen: flying it at once";
    enter(RecoveryPhase::kEscaping, why.str());
    decision_.escape_from = in.position;
    return true;
  }
  enter(RecoveryPhase::kTurning, why.str());
  return true;
}

bool DeadEndRecovery::route_since(const RecoveryInput& in, double since) {
  if (!(in.route_time > since) || !(in.route_time > narrow_route_time_)) return false;
  const bool leads = in.route == RouteKind::kForward || in.route == RouteKind::kBacktrack;
  if (leads && in.route_flyable && !in.route_flyable()) {
    narrow_route_time_ = in.route_time;  // the planner was told: wait for its next route
    return false;
  }
  return true;
}

void DeadEndRecovery::climb_or_hold(const RecoveryInput& in, const std::string& why) {
  const double ceiling = settings_.climb_ceiling;
  if (!(settings_.climb_step > 0) || !(in.altitude + settings_.climb_tolerance < ceiling)) {
    enter(RecoveryPhase::kNoRoute, why + ": holding the hover");
    return;
  }
  const double altitude = std::min(in.altitude + settings_.climb_step, ceiling);
  std::ostringstream text;
  text << why << ": climbing from " << in.altitude << " to " << altitude
       << " m to look over what the scanner saw from below";
  if (settings_.climb_through && altitude < ceiling)
    text << " (and on, while no route comes, to " << ceiling << " m)";
  begin_turn(in);  // the heading turns on the way up: counted from here
  enter(RecoveryPhase::kClimbing, text.str());
  decision_.climb_altitude = altitude;
  decision_.climb_target = settings_.climb_through ? ceiling : altitude;
  climb_start_ = in.time;
}

RecoveryDecision DeadEndRecovery::update(const RecoveryInput& in) {
  decision_.changed = false;
  decision_.reason.clear();
  if (!settings_.enabled) return decision_;
  if (!in.engaged) {
    // Guidance flies the leg: whatever happened, it is over.
    if (decision_.phase != RecoveryPhase::kIdle) enter(RecoveryPhase::kIdle, "avoidance ended");
    attempts_ = 0;
    stuck_since_.reset();
    near_spot_.reset();
    return decision_;
  }
  auto begin_look = [&](const char* why) {
    if (attempts_ >= settings_.max_attempts) {
      std::ostringstream text;
      text << why << " after " << attempts_ << " look-arounds: holding the hover, no route";
      enter(RecoveryPhase::kNoRoute, text.str());
      return;
    }
    ++attempts_;
    begin_turn(in);
    std::ostringstream text;
    text << why << ": hovering, looking around (" << attempts_ << " of " << settings_.max_attempts
         << ")";
    enter(RecoveryPhase::kLooking, text.str());
  };

  switch (decision_.phase) {
    case RecoveryPhase::kIdle:
      switch (stuck(in)) {
        case Stuck::kHovering:
          begin_look("no way forward");
          break;
        case Stuck::kNoProgress:
          begin_look("no progress (the plans move off, the vehicle stays)");
          break;
        case Stuck::kNo:
          break;
      }
      break;
    case RecoveryPhase::kLooking:
      if (!look_end_) {
        if (turned_through(in)) look_end_ = in.time;
      } else if (in.time - *look_end_ >= settings_.route_wait &&
                 route_since(in, *look_end_ - 1e-9)) {
        if (!take_route(in)) climb_or_hold(in, "no route after the look-around");
      } else if (in.time - *look_end_ >= settings_.route_timeout) {
        enter(RecoveryPhase::kNoRoute, "no new route after the look-around: holding the hover");
      }
      break;
    case RecoveryPhase::kTurning: {
      // The controller turns the heading the shorter way at its rate; what
      // follows starts once it faces the way it will fly (or after a full
      // turn, whatever it faces then: the map has been swept all round).
      const bool turned = turned_through(in);
      const bool facing = std::abs(wrap_angle(in.yaw - face_yaw_)) <= settings_.face_tolerance;
      if (facing && !facing_since_) facing_since_ = in.time;
      const bool done =
          (facing_since_ && in.time - *facing_since_ >= settings_.face_hold) || turned;
      if (done && after_turn_ == RecoveryPhase::kEscaping) {
        enter(RecoveryPhase::kEscaping, "facing the escape leg: flying it");
        decision_.escape_from = in.position;
      } else if (done) {
        enter(RecoveryPhase::kIdle, "facing along the leg: normal planning");
      }
      break;
    }
    case RecoveryPhase::kEscaping:
      if ((in.position - decision_.escape_point).norm() <= settings_.capture_radius &&
          in.velocity.norm() < settings_.hover_speed) {
        // A leg done is progress: the looks count again from none. On along
        // the route as it is now (it starts at the vehicle), or normal
        // planning when it advances from here.
        attempts_ = 0;
        if (!take_route(in)) enter(RecoveryPhase::kIdle, "escape leg done: normal planning");
      } else if (stuck(in) != Stuck::kNo)
        begin_look("the escape is stuck");
      break;
    case RecoveryPhase::kClimbing: {
      // A route the planner found on the way up is taken at once; else the
      // climb ends at its altitude (or where the time allowed got it) with
      // a look around. Only a climb done counts as progress: one the gate
      // refused leaves the looks counting to "no route".
      if (route_since(in, climb_start_) && take_route(in)) break;
      turned_through(in);
      const bool turned_all_round = std::abs(turned_) >= settings_.look_turn;
      const bool reached =
          std::abs(in.altitude - decision_.climb_altitude) <= settings_.climb_tolerance &&
          in.velocity.norm() < settings_.hover_speed;
      const double allowed =
          settings_.climb_step / std::max(in.max_vertical_speed, 1e-3) + settings_.climb_extra_time;
      const bool passing = decision_.climb_target > decision_.climb_altitude &&
                           in.altitude + settings_.climb_tolerance >= decision_.climb_altitude;
      if (passing && turned_all_round) {
        // Through a step with the look done on the way: a climb done (the
        // looks count from none again), and on to the next step without a
        // stop; the plan flown (to the ceiling) does not change.
        attempts_ = 0;
        const double next =
            std::min(decision_.climb_altitude + settings_.climb_step, settings_.climb_ceiling);
        std::ostringstream why;
        why << "climbed past " << decision_.climb_altitude
            << " m, the heading turned all round on the way and no route: on to " << next << " m";
        begin_turn(in);
        enter(RecoveryPhase::kClimbing, why.str());
        decision_.climb_altitude = next;
        climb_start_ = in.time;
        break;
      }
      if (reached) {
        attempts_ = 0;
        std::ostringstream why;
        why << "climbed to " << in.altitude << " m";
        if (turned_all_round) why << " (the heading turned all round on the way: the look is done)";
        begin_look(why.str().c_str());
        // The scanner has seen all round at every altitude of the climb:
        // another turn here would show nothing new, only the route is
        // waited for.
        if (turned_all_round) look_end_ = in.time;
      } else if (in.time - climb_start_ >= allowed) {
        std::ostringstream why;
        why << "the climb stopped at " << in.altitude << " m";
        begin_look(why.str().c_str());
      }
      break;
    }
    case RecoveryPhase::kNoRoute:
      // A route may appear later (an obstacle gone, a better map): taken up
      // while looks remain.
      if (attempts_ < settings_.max_attempts && route_since(in, look_start_)) take_route(in);
      break;
  }
  return decision_;
}

}  // namespace ofn::rh
