#include "ofn/rh_optimizer/narrow_passage.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace ofn::rh {
namespace {

// Gradient steps across the route per point; each is at most 0.5 m, so
// max_shift is reached well within them.
constexpr int kAscentSteps = 30;
constexpr double kMaxStep = 0.5;  // m
// Spacing of the samples over the cross-section before the ascent.
constexpr double kSampleSpacing = 0.5;  // m

// Whether `point` lies in the passage's cylinder.
bool inside(const NarrowPassage& passage, const Vec3& point) {
  const Vec3 d = point - passage.centre;
  return std::hypot(d.x(), d.y()) <= passage.radius && std::abs(d.z()) <= passage.half_height;
}

struct Crossing {
  bool passable = false;
  Vec3 best = Vec3::Zero();
  double best_distance = -1e300;
};

// Whether any point of the cross-section through `point` normal to
// `tangent` within `max_shift` of it has `required` clearance; `level`:
// only the horizontal line across the route at the point's altitude. The
// section is sampled every kSampleSpacing first (a gradient climb from the
// route point alone follows the slope up a nearby top and gives up, where
// a step sideways would have been clear), then the clearance is climbed
// from the best sample within the section. Where the section is passable,
// `best` is a point of it with the clearance: with `nearest`, the nearest
// sample that has it (or the point the climb reached).
Crossing cross(const ClearanceQuery& clearance, const Vec3& point, const Vec3& tangent,
               double required, double max_shift, bool level = false, bool nearest = false) {
  Crossing c;
  auto sample = [&](const Vec3& p) {
    const double d = clearance(p).distance;
    if (std::isfinite(d) && d > c.best_distance) {
      c.best_distance = d;
      c.best = p;
    }
    return std::isfinite(d) && d >= required;
  };
  if (sample(point)) {
    c.passable = true;
    return c;
  }
  // Across (horizontal) and, unless level, the section's other axis.
  Vec3 across = tangent.cross(Vec3::UnitZ());
  across = across.norm() > 1e-6 ? across.normalized() : Vec3::UnitX();
  const Vec3 other = across.cross(tangent).normalized();
  const int n = static_cast<int>(std::floor(max_shift / kSampleSpacing));
  std::vector<Vec3> offsets;
  for (int a = -n; a <= n; ++a)
    for (int b = level ? 0 : -n; b <= (level ? 0 : n); ++b) {
      const Vec3 offset = kSampleSpacing * (a * across + b * other);
      if (offset.norm() <= max_shift && (a != 0 || b != 0)) offsets.push_back(offset);
    }
  for (const Vec3& offset : offsets)
    if (sample(point + offset)) {
      c.passable = true;
      if (nearest) {
        // The nearest sample with the clearance (one exists: this one),
        // so that a stop moves no farther from its point than it must.
        std::stable_sort(offsets.begin(), offsets.end(), [](const Vec3& l, const Vec3& r) {
          return l.squaredNorm() < r.squaredNorm();
        });
        for (const Vec3& near : offsets) {
          const double d = clearance(point + near).distance;
          if (std::isfinite(d) && d >= required) {
            c.best = point + near;
            c.best_distance = d;
            break;
          }
        }
      }
      return c;
    }
  if (c.best_distance == -1e300) return c;
  Vec3 p = c.best;
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
    Vec3 up = d.gradient - d.gradient.dot(tangent) * tangent;
    if (level) up -= up.dot(other) * other;
    if (!up.allFinite() || up.norm() < 1e-6) return c;
    const Vec3 next = p + up.normalized() * std::min(kMaxStep, required - d.distance + 0.05);
    if ((next - point).norm() > max_shift) return c;
    p = next;
  }
  return c;
}

// Sets the passage's column: the altitudes about `point`, every
// extent_step out to max_extent up and down, at which `open` does not hold
// (the column's ends are known to a step; a step more above and below).
template <class Open>
void set_column(NarrowPassage& passage, const Vec3& point, const PassageSettings& settings,
                const Open& open) {
  auto extent = [&](double sign) {
    double reach = 0;
    for (double dz = settings.extent_step; dz <= settings.max_extent + 1e-9;
         dz += settings.extent_step) {
      if (open(point + Vec3(0.0, 0.0, sign * dz))) break;
      reach = dz;
    }
    return reach;
  };
  const double up = extent(-1.0), down = extent(1.0);  // NED: up is -z
  passage.centre.z() = point.z() + 0.5 * (down - up);
  passage.half_height = 0.5 * (up + down) + settings.extent_step;
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
    // point inside an obstacle).
    passage.radius = std::max(1.0, c.best_distance) + 0.5;
    // How far up and down the gap stays too narrow, crossed level at each
    // altitude: a gap between two tall obstacles is one all the way up to
    // the lower top, and a route at another altitude (a climbing vehicle's)
    // would otherwise run through it again just above or below.
    const Vec3 level_tangent = Vec3(direction.x(), direction.y(), 0.0).norm() > 1e-6
                                   ? Vec3(direction.x(), direction.y(), 0.0).normalized()
                                   : direction.normalized();
    // Searched about the route point, as the pinch was: about the widest
    // spot, up to max_shift aside, a section could reach a clear point
    // the route's own could not.
    set_column(passage, route[k], settings, [&](const Vec3& p) {
      return cross(clearance, p, level_tangent, required, settings.max_shift, true).passable;
    });
    // A pinch round the route's start (the vehicle, stopped in a narrow
    // spot) cannot be routed round: the planner lets routes leave it. Look
    // for one farther on.
    if (inside(passage, route.front())) continue;
    return passage;
  }
  return std::nullopt;
}

std::optional<Vec3> room_to_stop(const ClearanceQuery& clearance, const Vec3& point,
                                 double required, double max_shift) {
  if (!clearance || !point.allFinite()) return std::nullopt;
  // The section normal to the vertical is the horizontal disc round the
  // point.
  const Crossing c = cross(clearance, point, Vec3::UnitZ(), required, max_shift, false, true);
  if (!c.passable) return std::nullopt;
  return c.best;
}

std::optional<NarrowPassage> find_cramped_stop(const ClearanceQuery& clearance, const Vec3& stop,
                                               double required, const PassageSettings& settings) {
  if (!clearance || !settings.enabled || !stop.allFinite()) return std::nullopt;
  // The disc room_to_stop searches: any point of it within max_shift may be
  // where the stop is made.
  const Vec3 vertical = Vec3::UnitZ();
  const Crossing c = cross(clearance, stop, vertical, required, settings.max_shift);
  if (c.passable || c.best_distance == -1e300) return std::nullopt;
  NarrowPassage passage;
  // Round the stop, over the whole disc without room: a route that turns
  // anywhere in it would stop there. (Round the disc's widest spot with
  // that spot's clearance, as for a pinch, the zone held the vehicle 8 m
  // back on dense seed 171 and the corner was not reported.) A vehicle
  // inside sees the zone shrunk to its own distance from the axis (the
  // planner lets routes leave it), which still keeps routes off the stop.
  passage.centre = stop;
  passage.clearance = c.best_distance;
  passage.radius = settings.max_shift + 0.5;
  // The column in which there is no room either, as for a pinch.
  set_column(passage, stop, settings, [&](const Vec3& p) {
    return cross(clearance, p, vertical, required, settings.max_shift).passable;
  });
  return passage;
}

bool PassageMemory::add(const NarrowPassage& passage) {
  for (const NarrowPassage& known : passages_)
    if (inside(known, passage.centre)) return false;
  passages_.push_back(passage);
  if (capacity_ > 0 && static_cast<int>(passages_.size()) > capacity_)
    passages_.erase(passages_.begin());
  return true;
}

}  // namespace ofn::rh
