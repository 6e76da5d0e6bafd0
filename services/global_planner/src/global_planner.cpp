// Global path search (paper 4.2, Table 1). The search is exact over the graph
// build_graph() evaluates in full, but it only evaluates the segments it
// needs: a best-first form of the Eq. 9 recursion over optimistic lengths
// that tests a segment against the cuboids when it is about to fix a node's
// cost through it, with the cuboids bucketed on a horizontal grid.

#include "ofn/global_planner/global_planner.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <queue>
#include <stdexcept>
#include <unordered_map>
#include <utility>

namespace ofn::planning {

const char* to_string(PlanStatus status) {
  switch (status) {
    case PlanStatus::kOk:
      return "ok";
    case PlanStatus::kStartInside:
      return "start_inside";
    case PlanStatus::kGoalInside:
      return "goal_inside";
    case PlanStatus::kNoPath:
      return "no_path";
  }
  return "unknown";
}

namespace {

// A segment must gain this much along the leg (forward speed >= 0 with some
// margin, and Eq. 10 divides by the gain).
constexpr double kMinAdvance = 0.1;  // m
// Below this forward speed the velocity direction says nothing about the
// slope the first segment starts with.
constexpr double kMinSlopeSpeed = 0.5;  // m/s
// A segment exactly at the acceleration limit passes despite rounding.
constexpr double kAccelSlack = 1e-9;
constexpr double kInf = std::numeric_limits<double>::infinity();

struct Aabb {
  Vec3 lo;
  Vec3 hi;
};

Aabb inflated(const Aabb& box, double margin) {
  return {box.lo - Vec3::Constant(margin), box.hi + Vec3::Constant(margin)};
}

bool strictly_inside(const Aabb& box, const Vec3& p) {
  return (p.array() > box.lo.array()).all() && (p.array() < box.hi.array()).all();
}

// Chebyshev distance from p to the box (0 inside): the largest inflation of
// the box that leaves p outside.
double outside_distance(const Aabb& box, const Vec3& p) {
  const Vec3 gap = (box.lo - p).cwiseMax(p - box.hi);
  return std::max(0.0, gap.maxCoeff());
}

// Slab test of the segment p -> q against the closed box.
bool segment_meets(const Aabb& box, const Vec3& p, const Vec3& q) {
  double t_enter = 0.0;
  double t_exit = 1.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double d = q[axis] - p[axis];
    if (std::abs(d) < 1e-12) {
      if (p[axis] < box.lo[axis] || p[axis] > box.hi[axis]) return false;
      continue;
    }
    double ta = (box.lo[axis] - p[axis]) / d;
    double tb = (box.hi[axis] - p[axis]) / d;
    if (ta > tb) std::swap(ta, tb);
    t_enter = std::max(t_enter, ta);
    t_exit = std::min(t_exit, tb);
    if (t_enter > t_exit) return false;
  }
  return true;
}

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

/// Boxes bucketed on a horizontal grid (compressed rows), so that a segment
/// or point meets only the boxes of the cells it passes.
class BoxGrid {
 public:
  explicit BoxGrid(const std::vector<Aabb>& boxes) {
    if (boxes.empty()) return;
    double x_lo = kInf, y_lo = kInf, x_hi = -kInf, y_hi = -kInf;
    for (const Aabb& b : boxes) {
      x_lo = std::min(x_lo, b.lo.x());
      y_lo = std::min(y_lo, b.lo.y());
      x_hi = std::max(x_hi, b.hi.x());
      y_hi = std::max(y_hi, b.hi.y());
    }
    // About one box per cell keeps both the cell lists and the cells a
    // segment crosses short.
    const double area = std::max(1.0, (x_hi - x_lo) * (y_hi - y_lo));
    cell_ = std::max(1.0, std::sqrt(area / static_cast<double>(boxes.size())));
    cell_ = std::max({cell_, (x_hi - x_lo) / kMaxCells, (y_hi - y_lo) / kMaxCells});
    x0_ = x_lo;
    y0_ = y_lo;
    nx_ = std::max(1, static_cast<int>(std::ceil((x_hi - x_lo) / cell_)));
    ny_ = std::max(1, static_cast<int>(std::ceil((y_hi - y_lo) / cell_)));
    std::vector<int> counts(static_cast<size_t>(nx_) * ny_ + 1, 0);
    auto for_cells = [&](const Aabb& b, auto&& visit) {
      const int ix0 = clamp_x(b.lo.x()), ix1 = clamp_x(b.hi.x());
      const int iy0 = clamp_y(b.lo.y()), iy1 = clamp_y(b.hi.y());
      for (int ix = ix0; ix <= ix1; ++ix)
        for (int iy = iy0; iy <= iy1; ++iy) visit(ix * ny_ + iy);
    };
    for (const Aabb& b : boxes) for_cells(b, [&](int c) { ++counts[c + 1]; });
    for (size_t c = 1; c < counts.size(); ++c) counts[c] += counts[c - 1];
    cell_start_ = counts;
    items_.resize(static_cast<size_t>(counts.back()));
    for (size_t i = 0; i < boxes.size(); ++i)
      for_cells(boxes[i], [&](int c) { items_[counts[c]++] = static_cast<int>(i); });
  }

  /// Calls visit(box index) for every box whose cells the horizontal
  /// projection of p -> q passes (a box may come more than once).
  template <class Visit>
  void along_segment(const Vec3& p, const Vec3& q, Visit&& visit) const {
    if (items_.empty()) return;
    const double x_min = std::min(p.x(), q.x()), x_max = std::max(p.x(), q.x());
    const double y_min = std::min(p.y(), q.y()), y_max = std::max(p.y(), q.y());
    if (x_max < x0_ || x_min > x0_ + nx_ * cell_ || y_max < y0_ || y_min > y0_ + ny_ * cell_)
      return;
    const double dx = q.x() - p.x();
    const int ix0 = clamp_x(x_min), ix1 = clamp_x(x_max);
    for (int ix = ix0; ix <= ix1; ++ix) {
      // The y extent of the segment within this column of cells.
      double ya = y_min, yb = y_max;
      if (std::abs(dx) > 1e-9) {
        const double xa = std::max(x_min, x0_ + ix * cell_);
        const double xb = std::min(x_max, x0_ + (ix + 1) * cell_);
        const double y_at_a = p.y() + (xa - p.x()) / dx * (q.y() - p.y());
        const double y_at_b = p.y() + (xb - p.x()) / dx * (q.y() - p.y());
        ya = std::min(y_at_a, y_at_b);
        yb = std::max(y_at_a, y_at_b);
      }
      if (yb < y0_ || ya > y0_ + ny_ * cell_) continue;
      const int iy0 = clamp_y(ya), iy1 = clamp_y(yb);
      for (int iy = iy0; iy <= iy1; ++iy) {
        const int c = ix * ny_ + iy;
        for (int k = cell_start_[c]; k < cell_start_[c + 1]; ++k) visit(items_[k]);
      }
    }
  }

  template <class Visit>
  void at_point(const Vec3& p, Visit&& visit) const {
    along_segment(p, p, visit);
  }

 private:
  static constexpr double kMaxCells = 256.0;
  int clamp_x(double x) const {
    return std::clamp(static_cast<int>(std::floor((x - x0_) / cell_)), 0, nx_ - 1);
  }
  int clamp_y(double y) const {
    return std::clamp(static_cast<int>(std::floor((y - y0_) / cell_)), 0, ny_ - 1);
  }

  double x0_ = 0, y0_ = 0, cell_ = 1;
  int nx_ = 0, ny_ = 0;
  std::vector<int> cell_start_;
  std::vector<int> items_;
};

/// Steps 1-6 for one request: the kept cuboids, the nodes, and the segment
/// tests. Everything here lives for one call only (step 9).
class Problem {
 public:
  Problem(const GlobalPlannerConfig& config, const PlanRequest& request)
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

  int ignored() const { return ignored_; }
  int start_holder() const { return start_holder_; }
  int goal_holder() const { return goal_holder_; }
  int holder_id(int kept_index) const { return boxes_[kept_index].id; }
  const std::vector<Vec3>& nodes() const { return nodes_; }
  int size() const { return static_cast<int>(nodes_.size()); }
  double along(int i) const { return along_[i]; }
  int segments_checked() const { return segments_checked_; }

  double length(int i, int j) const { return (nodes_[j] - nodes_[i]).norm(); }

  /// Whether i -> j is a segment of the graph apart from the cuboids: it
  /// advances along the leg and passes the Eq. 10 check.
  bool shape_ok(int i, int j) const {
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

  /// When the goal is not ahead of the start along the leg, the only
  /// segment is the direct one (a vehicle that overshot still gets a path).
  bool goal_ahead() const { return guidance_[1].x() - guidance_[0].x() > kMinAdvance; }

  /// Whether i -> j cuts a cuboid (clearance box shrunk by the tolerance,
  /// or less around a start or goal that is already inside it).
  bool blocked(int i, int j) {
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

 private:
  // Largest |y''| at the ends of the cubic y(x) over [0, run] from 0 to
  // rise with end slopes slope0 and 0 (Eq. 10: the curvature is linear in x).
  static double max_end_curvature(double rise, double run, double slope0) {
    const double a2 = (3.0 * rise - 2.0 * slope0 * run) / (run * run);
    const double a3 = (-2.0 * rise + slope0 * run) / (run * run * run);
    return std::max(std::abs(2.0 * a2), std::abs(2.0 * a2 + 6.0 * a3 * run));
  }

  std::vector<Aabb> keep_boxes(const std::vector<ObstacleBox>& obstacles) {
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

  void find_holders() {
    for (size_t b = 0; b < boxes_.size(); ++b) {
      if (start_holder_ < 0 && outside_distance(raw_[b], start_) <= 0.0)
        start_holder_ = static_cast<int>(b);
      if (goal_holder_ < 0 && outside_distance(raw_[b], goal_) <= 0.0)
        goal_holder_ = static_cast<int>(b);
    }
  }

  // A start or goal inside a clearance box sees that box inflated only to
  // its own distance from it minus the tolerance, so it can still leave.
  std::vector<double> reliefs(const Vec3& p) const {
    std::vector<double> out(boxes_.size(), kInf);
    for (size_t b = 0; b < boxes_.size(); ++b)
      if (strictly_inside(solid_[b], p))
        out[b] = outside_distance(raw_[b], p) - config_.collision_tolerance;
    return out;
  }

  // As reliefs(), for the no-go zones: a point inside one sees it shrunk
  // to the point's horizontal distance from its axis, less the tolerance.
  std::vector<double> zone_reliefs(const Vec3& p) const {
    std::vector<double> out(zones_.size(), kInf);
    for (size_t z = 0; z < zones_.size(); ++z) {
      const double distance = zone_approach(zones_[z], p, p);
      if (distance < zones_[z].radius)
        out[z] = std::max(0.0, distance - config_.collision_tolerance);
    }
    return out;
  }

  double ground_z(double altitude) const { return -(config_.ground_altitude + altitude); }

  // Altitude (as world z) of the straight start -> goal line above the
  // horizontal point (x, y), clamped to the altitude band.
  double line_z(double x, double y) const {
    const Eigen::Vector2d s(start_.x(), start_.y());
    const Eigen::Vector2d d = Eigen::Vector2d(goal_.x(), goal_.y()) - s;
    double t = 0.0;
    if (d.squaredNorm() > 1e-12)
      t = std::clamp((Eigen::Vector2d(x, y) - s).dot(d) / d.squaredNorm(), 0.0, 1.0);
    const double z = start_.z() + t * (goal_.z() - start_.z());
    return std::clamp(z, ground_z(config_.max_altitude), ground_z(config_.min_altitude));
  }

  void place_nodes() {
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
  void add_line_crossings(const Aabb& c, double z, std::vector<Vec3>& out) const {
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
  bool lift_out(Vec3& p) const {
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

  static int64_t cell_key(const Vec3& p, double size, int dx, int dy, int dz) {
    const auto cell = [&](double v, int offset) {
      return static_cast<int64_t>(std::floor(v / size)) + offset;
    };
    return ((cell(p.x(), dx) & 0x1FFFFF) << 42) | ((cell(p.y(), dy) & 0x1FFFFF) << 21) |
           (cell(p.z(), dz) & 0x1FFFFF);
  }

  void add_to_merge_index(int i) {
    if (config_.merge_distance <= 0) return;
    merge_index_[cell_key(nodes_[i], config_.merge_distance, 0, 0, 0)].push_back(i);
  }

  bool has_neighbour(const Vec3& p) const {
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

  const GlobalPlannerConfig& config_;
  GuidanceFrame frame_;
  Vec3 start_, goal_;
  std::pair<double, double> start_slopes_{0.0, 0.0};
  int ignored_ = 0;
  std::vector<ObstacleBox> boxes_;
  std::vector<Aabb> raw_, clear_, solid_;
  BoxGrid grid_;
  std::vector<double> relief_start_, relief_goal_;
  std::vector<NoGoZone> zones_;
  std::vector<double> zone_relief_start_, zone_relief_goal_;
  int start_holder_ = -1, goal_holder_ = -1;
  std::vector<Vec3> nodes_, guidance_;
  std::vector<double> along_;
  std::unordered_map<int64_t, std::vector<int>> merge_index_;
  std::vector<uint32_t> stamp_;
  uint32_t query_ = 0;
  int segments_checked_ = 0;
};

/// Node 0 -> node 1 by the parents the search closed them with; empty when
/// the goal (node 1) was never reached.
std::vector<int> sequence_to_goal(const std::vector<char>& closed, const std::vector<int>& parent) {
  if (!closed[1]) return {};
  std::vector<int> sequence;
  for (int v = 1; v >= 0; v = parent[v]) sequence.push_back(v);
  std::reverse(sequence.begin(), sequence.end());
  return sequence;
}

struct Entry {
  double f;  // cost so far plus the straight distance to the goal
  double g;
  int node;
  int parent;
  bool exhaustive;  // queued after the node's best candidate proved blocked
  bool operator>(const Entry& o) const { return f > o.f; }
};

/// Shortest node sequence 0 -> 1 (Eq. 9) over the graph whose segments
/// exist where shape_ok() holds and cost their length unless blocked().
/// Best-first with the straight distance to the goal as the (consistent)
/// estimate; a segment is tested against the cuboids only when it is about
/// to fix a node's cost. Each open node first carries only its best
/// candidate parent; after that one proves blocked, every closed parent is
/// queued for it, so no blocked segment is ever tested twice.
std::vector<int> search(Problem& problem) {
  const int n = problem.size();
  const Vec3 goal = problem.nodes()[1];
  std::vector<double> h(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) h[i] = (goal - problem.nodes()[i]).norm();

  // Only nodes strictly between the start and the goal along the leg can
  // lie on a path; sorted along the leg so a closed node scans only those
  // ahead of it.
  std::vector<int> ahead;
  if (problem.goal_ahead()) {
    const double lo = problem.along(0) + kMinAdvance, hi = problem.along(1) - kMinAdvance;
    for (int i = 2; i < n; ++i)
      if (problem.along(i) > lo && problem.along(i) < hi) ahead.push_back(i);
  }
  ahead.push_back(1);
  std::sort(ahead.begin(), ahead.end(),
            [&](int a, int b) { return problem.along(a) < problem.along(b); });
  std::vector<double> ahead_x(ahead.size());
  for (size_t k = 0; k < ahead.size(); ++k) ahead_x[k] = problem.along(ahead[k]);

  std::vector<double> g(n, kInf), best_offer(n, kInf);
  std::vector<int> parent(n, -1), offer_parent(n, -1);
  std::vector<char> closed(n, 0), exhaustive(n, 0);
  std::vector<int> closed_list;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;

  auto close = [&](int v, double cost, int from) {
    closed[v] = 1;
    g[v] = cost;
    parent[v] = from;
    closed_list.push_back(v);
    const double x_from = problem.along(v) + kMinAdvance;
    auto first = std::upper_bound(ahead_x.begin(), ahead_x.end(), x_from) - ahead_x.begin();
    if (v == 0) first = 0;
    for (size_t k = static_cast<size_t>(first); k < ahead.size(); ++k) {
      const int w = ahead[k];
      if (closed[w]) continue;
      const double offer = cost + problem.length(v, w);
      if (!exhaustive[w] && offer >= best_offer[w]) continue;
      if (!problem.shape_ok(v, w)) continue;
      if (!exhaustive[w]) {
        best_offer[w] = offer;
        offer_parent[w] = v;
      }
      open.push({offer + h[w], offer, w, v, exhaustive[w] != 0});
    }
  };

  close(0, 0.0, -1);
  while (!open.empty()) {
    const Entry e = open.top();
    open.pop();
    if (closed[e.node]) continue;
    // Stale: a better candidate replaced it, or it was queued before the
    // switch and its parent has been queued again since.
    if (exhaustive[e.node] ? !e.exhaustive
                           : (e.parent != offer_parent[e.node] || e.g != best_offer[e.node]))
      continue;
    if (!problem.blocked(e.parent, e.node)) {
      if (e.node == 1) {
        g[1] = e.g;
        parent[1] = e.parent;
        closed[1] = 1;
        break;
      }
      close(e.node, e.g, e.parent);
      continue;
    }
    if (exhaustive[e.node]) continue;
    exhaustive[e.node] = 1;
    for (int u : closed_list) {
      if (u == e.parent || !problem.shape_ok(u, e.node)) continue;
      const double offer = g[u] + problem.length(u, e.node);
      open.push({offer + h[e.node], offer, e.node, u, true});
    }
  }
  return sequence_to_goal(closed, parent);
}

/// Shortest node sequence 0 -> 1 with segments in any direction: the way
/// out of a dead end, which turns back along the leg, and which search()
/// (every segment advancing) cannot find. No Eq. 10 check: the vehicle
/// starts it from a hover. Best-first with lazy segment tests as search(),
/// but without pruning by the best offer (a node keeps every candidate
/// parent until one proves clear), which is simpler and fast enough for a
/// search run only after the forward one failed.
std::vector<int> search_any_direction(Problem& problem) {
  const int n = problem.size();
  const Vec3 goal = problem.nodes()[1];
  std::vector<int> parent(n, -1);
  std::vector<char> closed(n, 0);
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
  // Closes v at `cost` by way of `from` and offers every open node from it
  // (the goal closes the search instead).
  auto close = [&](int v, double cost, int from) {
    closed[v] = 1;
    parent[v] = from;
    if (v == 1) return;
    for (int w = 1; w < n; ++w) {
      if (closed[w] || w == v) continue;
      const double offer = cost + problem.length(v, w);
      open.push({offer + (goal - problem.nodes()[w]).norm(), offer, w, v, false});
    }
  };
  close(0, 0.0, -1);
  while (!open.empty() && !closed[1]) {
    const Entry e = open.top();
    open.pop();
    if (!closed[e.node] && !problem.blocked(e.parent, e.node)) close(e.node, e.g, e.parent);
  }
  return sequence_to_goal(closed, parent);
}

std::vector<Vec3> interpolate(const std::vector<Vec3>& waypoints, double spacing) {
  std::vector<Vec3> path;
  if (waypoints.empty()) return path;
  path.push_back(waypoints.front());
  for (size_t k = 1; k < waypoints.size(); ++k) {
    const Vec3& a = waypoints[k - 1];
    const Vec3& b = waypoints[k];
    const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / spacing)));
    for (int s = 1; s < steps; ++s) path.push_back(a + (b - a) * (static_cast<double>(s) / steps));
    path.push_back(b);
  }
  return path;
}

}  // namespace

GlobalPlanner::GlobalPlanner(GlobalPlannerConfig config) : config_(config) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(config_.clearance) || !positive(config_.speed) || !positive(config_.max_accel) ||
      !positive(config_.path_spacing))
    throw std::invalid_argument(
        "global planner: clearance, speed, max_accel and path_spacing must be positive");
  if (!(config_.min_altitude < config_.max_altitude))
    throw std::invalid_argument("global planner: min_altitude must be below max_altitude");
}

PlanResult GlobalPlanner::plan(const PlanRequest& request) {
  return plan_with(request, /*any_direction=*/false);
}

PlanResult GlobalPlanner::plan_any_direction(const PlanRequest& request) {
  return plan_with(request, /*any_direction=*/true);
}

PlanResult GlobalPlanner::plan_with(const PlanRequest& request, bool any_direction) {
  Problem problem(config_, request);
  PlanResult result;
  result.nodes = problem.size();
  result.ignored_obstacles = problem.ignored();
  if (problem.start_holder() >= 0) {
    result.status = PlanStatus::kStartInside;
    result.blocking_obstacle = problem.holder_id(problem.start_holder());
    return result;
  }
  if (problem.goal_holder() >= 0) {
    result.status = PlanStatus::kGoalInside;
    result.blocking_obstacle = problem.holder_id(problem.goal_holder());
    return result;
  }
  const std::vector<int> sequence = any_direction ? search_any_direction(problem) : search(problem);
  result.segments_checked = problem.segments_checked();
  if (sequence.empty()) {
    result.status = PlanStatus::kNoPath;
    return result;
  }
  result.status = PlanStatus::kOk;
  result.cost = 0.0;
  for (size_t k = 0; k < sequence.size(); ++k) {
    result.waypoints.push_back(problem.nodes()[sequence[k]]);
    if (k > 0) result.cost += problem.length(sequence[k - 1], sequence[k]);
  }
  result.path = interpolate(result.waypoints, config_.path_spacing);
  return result;
}

PlanGraph GlobalPlanner::build_graph(const PlanRequest& request) const {
  Problem problem(config_, request);
  PlanGraph graph;
  graph.nodes = problem.nodes();
  const int n = problem.size();
  graph.cost.assign(static_cast<size_t>(n) * n, PlanGraph::kBlocked);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      if (i == j || j == 0 || i == 1 || !problem.shape_ok(i, j)) continue;
      if (!problem.blocked(i, j)) graph.cost[static_cast<size_t>(i) * n + j] = problem.length(i, j);
    }
  return graph;
}

}  // namespace ofn::planning
