// Steps 1-6 of Table 1 for one request (see cuboid_graph.hpp).

#include "ofn/global_planner/cuboid_graph.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace ofn::planning {

namespace {

// Below this forward speed the velocity direction says nothing about the
// slope the first segment starts with.
constexpr double kMinSlopeSpeed = 0.5;  // m/s
// A segment exactly at the acceleration limit passes despite rounding.
constexpr double kAccelSlack = 1e-9;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Horizontal distance from the zone's axis to the part of p -> q within
// its height; infinity when no part is.
double zone_approach(const NoGoZone& zone, const Vec3& p, const Vec3& q) {
  const double lo = zone.centre.z() - zone.half_height;
  const double hi = zone.centre.z() + zone.half_height;
  double t0 = 0.0, t1 = 1.0;
  const double dz = q.z() - p.z();
  if (std::abs(dz) < 1e-12) {
    if (p.z() < lo || p.z() > hi) return kInf;
  } else {
    double ta = (lo - p.z()) / dz;
    double tb = (hi - p.z()) / dz;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return kInf;
  }
  const Eigen::Vector2d c = zone.centre.head<2>();
  const Eigen::Vector2d a = p.head<2>() + t0 * (q - p).head<2>();
  const Eigen::Vector2d b = p.head<2>() + t1 * (q - p).head<2>();
  const Eigen::Vector2d ab = b - a;
  double t = 0.0;
  if (ab.squaredNorm() > 1e-12) t = std::clamp((c - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (a + t * ab - c).norm();
}

bool valid_zone(const NoGoZone& zone) {
  return zone.centre.allFinite() && std::isfinite(zone.radius) && std::isfinite(zone.half_height) &&
         zone.radius > 0 && zone.half_height > 0;
}

bool valid_box(const ObstacleBox& box) {
  return box.min_corner.allFinite() && box.max_corner.allFinite() &&
         (box.min_corner.array() < box.max_corner.array()).all();
}

// Largest |y''| at the ends of the cubic y(x) over [0, run] from 0 to
// rise with end slopes slope0 and 0 (Eq. 10: the curvature is linear in x).
double max_end_curvature(double rise, double run, double slope0) {
  const double a2 = (3.0 * rise - 2.0 * slope0 * run) / (run * run);
  const double a3 = (-2.0 * rise + slope0 * run) / (run * run * run);
  return std::max(std::abs(2.0 * a2), std::abs(2.0 * a2 + 6.0 * a3 * run));
}

int64_t cell_key(const Vec3& p, double size, int dx, int dy, int dz) {
  const auto cell = [&](double v, int offset) {
    return static_cast<int64_t>(std::floor(v / size)) + offset;
  };
  return ((cell(p.x(), dx) & 0x1FFFFF) << 42) | ((cell(p.y(), dy) & 0x1FFFFF) << 21) |
         (cell(p.z(), dz) & 0x1FFFFF);
}

}  // namespace

CuboidGraph::CuboidGraph(const GlobalPlannerConfig& config, const PlanRequest& request)
    : config_(config),
      frame_(GuidanceFrame::from_leg(request.leg_from, request.goal)),
      start_(request.start),
      goal_(request.goal),
      grid_(keep_boxes(request.obstacles)) {
  if (!request.start.allFinite() || !request.start_velocity.allFinite() ||
      !request.goal.allFinite() || !request.leg_from.allFinite())
    throw std::invalid_argument(
        "global planner: start, velocity, goal and leg_from must be finite");
  const Vec3 v = frame_.world_from_guidance.transpose() * request.start_velocity;
  if (v.x() >= kMinSlopeSpeed) start_slopes_ = {v.y() / v.x(), v.z() / v.x()};
  stamp_.assign(boxes_.size(), 0);
  find_holders();
  relief_start_ = reliefs(start_);
  relief_goal_ = reliefs(goal_);
  for (const NoGoZone& zone : request.no_go)
    if (valid_zone(zone)) zones_.push_back(zone);
  zone_relief_start_ = zone_reliefs(start_);
  zone_relief_goal_ = zone_reliefs(goal_);
  place_nodes();
}

bool CuboidGraph::shape_ok(int i, int j) const {
  const Vec3 d = guidance_[j] - guidance_[i];
  if (i == 0 && j == 1 && !goal_ahead()) return true;
  if (d.x() <= kMinAdvance) return false;
  if (i != 0 && !config_.accel_check_all_segments) return true;
  const double slope_y = i == 0 ? start_slopes_.first : 0.0;
  const double slope_z = i == 0 ? start_slopes_.second : 0.0;
  const double v2 = config_.speed * config_.speed;
  const double a_y = v2 * max_end_curvature(d.y(), d.x(), slope_y);
  const double a_z = v2 * max_end_curvature(d.z(), d.x(), slope_z);
  return std::hypot(a_y, a_z) <= config_.max_accel * (1.0 + kAccelSlack);
}

bool CuboidGraph::blocked(int i, int j) {
  ++segments_checked_;
  ++query_;
  const Vec3& p = nodes_[i];
  const Vec3& q = nodes_[j];
  const bool from_start = i == 0, to_goal = j == 1;
  bool hit = false;
  grid_.along_segment(p, q, [&](int b) {
    if (hit || stamp_[b] == query_) return;
    stamp_[b] = query_;
    double relief = kInf;
    if (from_start) relief = std::min(relief, relief_start_[b]);
    if (to_goal) relief = std::min(relief, relief_goal_[b]);
    if (relief < kInf) {
      const Aabb box = inflated(raw_[b], relief);
      hit = (box.lo.array() < box.hi.array()).all() && segment_meets(box, p, q);
    } else {
      hit = segment_meets(solid_[b], p, q);
    }
  });
  for (size_t z = 0; z < zones_.size() && !hit; ++z) {
    double radius = zones_[z].radius;
    if (from_start) radius = std::min(radius, zone_relief_start_[z]);
    if (to_goal) radius = std::min(radius, zone_relief_goal_[z]);
    hit = zone_approach(zones_[z], p, q) < radius;
  }
  return hit;
}

std::vector<Aabb> CuboidGraph::keep_boxes(const std::vector<ObstacleBox>& obstacles) {
  std::vector<const ObstacleBox*> valid;
  valid.reserve(obstacles.size());
  for (const ObstacleBox& o : obstacles) {
    if (valid_box(o))
      valid.push_back(&o);
    else
      ++ignored_;
  }
  const size_t limit = static_cast<size_t>(std::max(0, config_.max_obstacles));
  if (valid.size() > limit) {
    auto distance = [&](const ObstacleBox* o) {
      return (start_.cwiseMax(o->min_corner).cwiseMin(o->max_corner) - start_).squaredNorm();
    };
    std::nth_element(
        valid.begin(), valid.begin() + static_cast<long>(limit), valid.end(),
        [&](const ObstacleBox* a, const ObstacleBox* b) { return distance(a) < distance(b); });
    ignored_ += static_cast<int>(valid.size() - limit);
    valid.resize(limit);
  }
  const double c = config_.clearance;
  for (const ObstacleBox* o : valid) {
    boxes_.push_back(*o);
    raw_.push_back({o->min_corner, o->max_corner});
    clear_.push_back(inflated(raw_.back(), c));
    solid_.push_back(inflated(raw_.back(), c - config_.collision_tolerance));
  }
  return clear_;
}

void CuboidGraph::find_holders() {
  for (size_t b = 0; b < boxes_.size(); ++b) {
    if (start_holder_ < 0 && outside_distance(raw_[b], start_) <= 0.0)
      start_holder_ = static_cast<int>(b);
    if (goal_holder_ < 0 && outside_distance(raw_[b], goal_) <= 0.0)
      goal_holder_ = static_cast<int>(b);
  }
}

// A start or goal inside a clearance box sees that box inflated only to
// its own distance from it minus the tolerance, so it can still leave.
std::vector<double> CuboidGraph::reliefs(const Vec3& p) const {
  std::vector<double> out(boxes_.size(), kInf);
  for (size_t b = 0; b < boxes_.size(); ++b)
    if (strictly_inside(solid_[b], p))
      out[b] = outside_distance(raw_[b], p) - config_.collision_tolerance;
  return out;
}

// As reliefs(), for the no-go zones: a point inside one sees it shrunk
// to the point's horizontal distance from its axis, less the tolerance.
std::vector<double> CuboidGraph::zone_reliefs(const Vec3& p) const {
  std::vector<double> out(zones_.size(), kInf);
  for (size_t z = 0; z < zones_.size(); ++z) {
    const double distance = zone_approach(zones_[z], p, p);
    if (distance < zones_[z].radius) out[z] = std::max(0.0, distance - config_.collision_tolerance);
  }
  return out;
}

// Altitude (as world z) of the straight start -> goal line above the
// horizontal point (x, y), clamped to the altitude band.
double CuboidGraph::line_z(double x, double y) const {
  const Eigen::Vector2d s(start_.x(), start_.y());
  const Eigen::Vector2d d = Eigen::Vector2d(goal_.x(), goal_.y()) - s;
  double t = 0.0;
  if (d.squaredNorm() > 1e-12)
    t = std::clamp((Eigen::Vector2d(x, y) - s).dot(d) / d.squaredNorm(), 0.0, 1.0);
  const double z = start_.z() + t * (goal_.z() - start_.z());
  return std::clamp(z, ground_z(config_.max_altitude), ground_z(config_.min_altitude));
}

void CuboidGraph::place_nodes() {
  std::vector<Vec3> candidates;
  candidates.reserve(boxes_.size() * 10);
  const double top_limit = ground_z(config_.max_altitude);
  const double floor_z = ground_z(config_.min_altitude);
  for (size_t b = 0; b < boxes_.size(); ++b) {
    const Aabb& c = clear_[b];
    const double xs[2] = {c.lo.x(), c.hi.x()};
    const double ys[2] = {c.lo.y(), c.hi.y()};
    for (double x : xs)
      for (double y : ys) candidates.emplace_back(x, y, line_z(x, y));
    if (!boxes_[b].top_observed || c.lo.z() < top_limit) continue;
    const double top_z = std::min(c.lo.z(), floor_z);
    for (double x : xs)
      for (double y : ys) candidates.emplace_back(x, y, top_z);
    add_line_crossings(c, top_z, candidates);
  }

  // Step 4 before step 3: a node that is about to be dropped must not
  // absorb a neighbour that would have survived.
  std::vector<Vec3> lifted;
  lifted.reserve(candidates.size());
  for (Vec3 p : candidates)
    if (lift_out(p)) lifted.push_back(p);

  std::vector<std::pair<double, int>> order;
  order.reserve(lifted.size());
  for (size_t i = 0; i < lifted.size(); ++i)
    order.emplace_back((lifted[i] - start_).squaredNorm(), static_cast<int>(i));
  std::sort(order.begin(), order.end());

  nodes_ = {start_, goal_};
  // Only corner nodes go into the merge index, so only they absorb their
  // neighbours. The start and the goal are not corners: a vehicle stopped
  // 2 m beside the corner it must go round would lose that corner, and
  // the segment from where it is to the next one cuts the box (seen in
  // the cul-de-sac: the route flipped to the far side each time the
  // escape reached a corner).
  merge_index_.clear();
  for (const auto& entry : order) {
    const Vec3& p = lifted[entry.second];
    if (config_.merge_distance > 0 && has_neighbour(p)) continue;
    nodes_.push_back(p);
    add_to_merge_index(static_cast<int>(nodes_.size()) - 1);
  }
  guidance_.reserve(nodes_.size());
  along_.reserve(nodes_.size());
  for (const Vec3& p : nodes_) {
    guidance_.push_back(frame_.to_guidance(p));
    along_.push_back(guidance_.back().x());
  }
}

// Where the horizontal start -> goal line enters and leaves the
// footprint, so a path straight over a wall exists.
void CuboidGraph::add_line_crossings(const Aabb& c, double z, std::vector<Vec3>& out) const {
  const Eigen::Vector2d s(start_.x(), start_.y());
  const Eigen::Vector2d d = Eigen::Vector2d(goal_.x(), goal_.y()) - s;
  if (d.squaredNorm() < 1e-12) return;
  double t_enter = -kInf, t_exit = kInf;
  for (int axis = 0; axis < 2; ++axis) {
    if (std::abs(d[axis]) < 1e-12) {
      if (s[axis] < c.lo[axis] || s[axis] > c.hi[axis]) return;
      continue;
    }
    double ta = (c.lo[axis] - s[axis]) / d[axis];
    double tb = (c.hi[axis] - s[axis]) / d[axis];
    if (ta > tb) std::swap(ta, tb);
    t_enter = std::max(t_enter, ta);
    t_exit = std::min(t_exit, tb);
  }
  if (t_enter > t_exit) return;
  for (double t : {t_enter, t_exit}) {
    const Eigen::Vector2d q = s + t * d;
    out.emplace_back(q.x(), q.y(), z);
  }
}

// Lifts p out of every clearance box it is inside (onto that box's top
// plus clearance); false when a top is unobserved or too high.
bool CuboidGraph::lift_out(Vec3& p) const {
  const double top_limit = ground_z(config_.max_altitude);
  for (size_t lifts = 0; lifts <= boxes_.size(); ++lifts) {
    int holder = -1;
    grid_.at_point(p, [&](int b) {
      if (holder < 0 && strictly_inside(solid_[b], p)) holder = b;
    });
    if (holder < 0) return true;
    if (!boxes_[holder].top_observed || clear_[holder].lo.z() < top_limit) return false;
    p.z() = clear_[holder].lo.z();
  }
  return false;
}

void CuboidGraph::add_to_merge_index(int i) {
  if (config_.merge_distance <= 0) return;
  merge_index_[cell_key(nodes_[i], config_.merge_distance, 0, 0, 0)].push_back(i);
}

bool CuboidGraph::has_neighbour(const Vec3& p) const {
  const double r = config_.merge_distance;
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz) {
        const auto it = merge_index_.find(cell_key(p, r, dx, dy, dz));
        if (it == merge_index_.end()) continue;
        for (int k : it->second)
          if ((nodes_[k] - p).squaredNorm() < r * r) return true;
      }
  return false;
}

}  // namespace ofn::planning
