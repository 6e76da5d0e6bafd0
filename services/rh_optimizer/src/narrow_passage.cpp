#include "ofn/rh_optimizer/narrow_passage.hpp"

#include <algorithm>
#include <cmath>

namespace ofn::rh {
namespace {

// Gradient steps across the route per point; each is at most 0.5 m, so
// max_shift is reached well within them.
constexpr int kAscentSteps = 30;
constexpr double kMaxStep = 0.5;  // m

struct Crossing {
  bool passable = false;
  Vec3 best = Vec3::Zero();
  double best_distance = -1e300;
};

// Climbs the clearance within the plane through `point` normal to
// `tangent`, at most `max_shift` from `point`.
Crossing cross(const ClearanceQuery& clearance, const Vec3& point, const Vec3& tangent,
               double required, double max_shift) {
  Crossing c;
  Vec3 p = point;
  for (int i = 0; i < kAscentSteps; ++i) {
    const mapping::DistanceSample d = clearance(p);
    if (!std::isfinite(d.distance)) return c;
    if (d.distance > c.best_distance) {
      c.best_distance = d.distance;
      c.best = p;
    }
    if (d.distance >= required) {
      c.passable = true;
      return c;
    }
    Vec3 across = d.gradient - d.gradient.dot(tangent) * tangent;
    if (!across.allFinite() || across.norm() < 1e-6) return c;
    const Vec3 next = p + across.normalized() * std::min(kMaxStep, required - d.distance + 0.05);
    if ((next - point).norm() > max_shift) return c;
    p = next;
  }
  return c;
}

}  // namespace

std::optional<NarrowPassage> find_narrow_passage(const ClearanceQuery& clearance,
                                                 const std::vector<Vec3>& route, double required,
                                                 const PassageSettings& settings) {
  if (!clearance || !settings.enabled || route.size() < 2) return std::nullopt;
  double along = 0;
  for (size_t k = 0; k < route.size(); ++k) {
    if (k > 0) along += (route[k] - route[k - 1]).norm();
    if (along > settings.look_distance) break;
    const Vec3& ahead = route[std::min(k + 1, route.size() - 1)];
    const Vec3& behind = route[k == 0 ? 0 : k - 1];
    const Vec3 direction = ahead - behind;
    if (!route[k].allFinite() || !direction.allFinite() || direction.norm() < 1e-6) continue;
    const Crossing c =
        cross(clearance, route[k], direction.normalized(), required, settings.max_shift);
    if (c.passable || c.best_distance == -1e300) continue;
    NarrowPassage passage;
    passage.centre = c.best;
    passage.clearance = c.best_distance;
    // A route through the pinch crosses the plane where it is free: within
    // the widest spot's clearance of it (at least a metre, for a route
    // point inside an obstacle). Above and below, the search reached
    // max_shift without the clearance.
    passage.radius = std::max(1.0, c.best_distance) + 0.5;
    passage.half_height = settings.max_shift;
    // A pinch round the route's start (the vehicle, stopped in a narrow
    // spot) cannot be routed round: the planner lets routes leave it. Look
    // for one farther on.
    const Vec3 from_start = route.front() - passage.centre;
    if (std::hypot(from_start.x(), from_start.y()) <= passage.radius &&
        std::abs(from_start.z()) <= passage.half_height)
      continue;
    return passage;
  }
  return std::nullopt;
}

bool PassageMemory::add(const NarrowPassage& passage) {
  for (const NarrowPassage& known : passages_) {
    const Vec3 d = passage.centre - known.centre;
    if (std::hypot(d.x(), d.y()) <= known.radius && std::abs(d.z()) <= known.half_height)
      return false;
  }
  passages_.push_back(passage);
  if (capacity_ > 0 && static_cast<int>(passages_.size()) > capacity_)
    passages_.erase(passages_.begin());
  return true;
}

}  // namespace ofn::rh
