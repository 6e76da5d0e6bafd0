#include "ofn/mapper/mapper_service.hpp"

#include <algorithm>

#include "ofn/common/channels.hpp"
#include "ofn/common/validate/nav_state.hpp"
#include "ofn/common/validate/scan_world.hpp"

namespace ofn::mapping {

MapperServiceConfig load_mapper_config(YamlReader& r) {
  MapperServiceConfig c;
  c.cuboid_rate = r.number_in("cuboid_rate_hz", c.cuboid_rate, 0.05, 50.0);
  c.scan_max_age = r.number_in("scan_max_age", c.scan_max_age, 0.01, 60.0);
  c.nav_max_age = r.number_in("nav_max_age", c.nav_max_age, 0.01, 60.0);
  c.grid_crop_border = static_cast<int>(r.integer("grid_crop_border", c.grid_crop_border));
  if (c.grid_crop_border < 0 || c.grid_crop_border > 1000)
    r.fail("grid_crop_border", "expected 0..1000 cells");
  auto& m = c.mapper;
  m.use_occupancy = r.boolean("use_occupancy", m.use_occupancy);
  m.confirm_probability = r.number_in("confirm_probability", m.confirm_probability, 0.5, 0.999);
  m.top_seen_band = r.number_in("top_seen_band", m.top_seen_band, 0.1, 100.0);
  m.top_over_hits = r.boolean("top_over_hits", m.top_over_hits);
  m.top_over_hits_margin = r.number_in("top_over_hits_margin", m.top_over_hits_margin, 0.0, 1.0);
  const double ground = r.number_in("ground_altitude", 0.0, -1e4, 1e4);

  YamlReader grid = r.child("grid");
  auto& g = m.grid;
  g.resolution = grid.number_in("resolution", g.resolution, 0.05, 20.0);
  g.half_extent = grid.number_in("half_extent", g.half_extent, 1.0, 2000.0);
  g.safety_margin = grid.number_in("safety_margin", g.safety_margin, 0.0, 100.0);
  g.smoothing_radius = static_cast<int>(grid.integer("smoothing_radius", g.smoothing_radius));
  if (g.smoothing_radius < 0 || g.smoothing_radius > 20)
    grid.fail("smoothing_radius", "expected 0..20 cells");
  g.ground_clearance = grid.number_in("ground_clearance", g.ground_clearance, 0.0, 100.0);
  g.ceiling = grid.number_in("ceiling", g.ceiling, 1.0, 1e4);
  g.ground_altitude = ground;
  if (g.half_extent / g.resolution > 1000) grid.fail("half_extent", "more than 2000 x 2000 cells");
  grid.finish();

  YamlReader occ = r.child("occupancy");
  auto& o = m.occupancy;
  o.resolution = occ.number_in("resolution", o.resolution, 0.05, 20.0);
  o.max_range = occ.number_in("max_range", o.max_range, 1.0, 1e4);
  o.prob_hit = occ.number_in("prob_hit", o.prob_hit, 0.5, 0.999);
  o.prob_miss = occ.number_in("prob_miss", o.prob_miss, 0.001, 0.5);
  o.clamp_min = occ.number_in("clamp_min", o.clamp_min, 0.001, 0.5);
  o.clamp_max = occ.number_in("clamp_max", o.clamp_max, 0.5, 0.9999);
  o.occupied_threshold = occ.number_in("occupied_threshold", o.occupied_threshold, 0.05, 0.95);
  o.forget_radius = occ.number_in("forget_radius", o.forget_radius, 1.0, 1e5);
  o.ground_altitude = ground;
  occ.finish();

  YamlReader cub = r.child("cuboids");
  auto& x = m.cuboids;
  x.height_threshold = cub.number_in("height_threshold", x.height_threshold, 0.0, 1e4);
  x.min_area = cub.number_in("min_area", x.min_area, 0.0, 1e6);
  x.min_fill = cub.number_in("min_fill", x.min_fill, 0.0, 1.0);
  x.min_split_size = cub.number_in("min_split_size", x.min_split_size, 0.1, 1e4);
  x.ground_altitude = ground;
  x.ceiling = g.ceiling;
  cub.finish();

  YamlReader db = r.child("database");
  auto& d = m.database;
  d.match_overlap = db.number_in("match_overlap", d.match_overlap, 0.0, 1.0);
  const int64_t misses = db.integer("retire_after_misses", d.retire_after_misses);
  if (misses < 1 || misses > 1000) db.fail("retire_after_misses", "expected 1..1000 cycles");
  d.retire_after_misses = static_cast<int>(misses);
  d.confidence_step = db.number_in("confidence_step", d.confidence_step, 0.01, 1.0);
  db.finish();
  r.finish();
  if (g.half_extent < o.max_range)
    r.fail("grid", "grid.half_extent must cover occupancy.max_range (the sensor's reach)");
  return c;
}

obstacle_grid_t grid_message(const Heightfield& f, double safety_margin, int border, Utime utime) {
  int r0 = f.rows, r1 = -1, c0 = f.cols, c1 = -1;
  for (int r = 0; r < f.rows; ++r)
    for (int c = 0; c < f.cols; ++c)
      if (f.at(r, c) > 0.0f) {
        r0 = std::min(r0, r);
        r1 = std::max(r1, r);
        c0 = std::min(c0, c);
        c1 = std::max(c1, c);
      }
  if (r1 < 0) {
    r0 = r1 = f.rows / 2;
    c0 = c1 = f.cols / 2;
  } else {
    r0 = std::max(0, r0 - border);
    c0 = std::max(0, c0 - border);
    r1 = std::min(f.rows - 1, r1 + border);
    c1 = std::min(f.cols - 1, c1 + border);
  }
  obstacle_grid_t m;
  m.utime = utime;
  m.frame = "NED";
  m.origin[0] = f.origin_north + r0 * f.resolution;
  m.origin[1] = f.origin_east + c0 * f.resolution;
  m.resolution = f.resolution;
  m.safety_margin = safety_margin;
  m.rows = r1 - r0 + 1;
  m.cols = c1 - c0 + 1;
  m.num_cells = m.rows * m.cols;
  m.top_altitude.resize(m.num_cells);
  for (int r = r0; r <= r1; ++r)
    for (int c = c0; c <= c1; ++c) m.top_altitude[(r - r0) * m.cols + (c - c0)] = f.at(r, c);
  return m;
}

cuboid_list_t cuboid_message(const std::vector<ObstacleEntry>& entries, Utime utime) {
  cuboid_list_t m;
  m.utime = utime;
  m.frame = "NED";
  m.num_cuboids = static_cast<int32_t>(entries.size());
  for (const auto& e : entries) {
    cuboid_t c;
    c.id = e.id;
    for (int k = 0; k < 3; ++k) {
      c.min_corner[k] = e.cuboid.min[k];
      c.max_corner[k] = e.cuboid.max[k];
    }
    c.top_observed = e.cuboid.top_observed;
    c.confidence = e.confidence;
    c.last_seen_utime = e.last_seen;
    m.cuboids.push_back(c);
  }
  return m;
}

MapperService::MapperService(lcm::LCM& lcm, const Clock& clock, MapperServiceConfig config)
    : node_("mapper", lcm, clock), config_(std::move(config)), mapper_(config_.mapper) {
  node_.subscribe<scan_world_t>(
      channels::kScanWorld, [this](const scan_world_t& m) { on_scan(m); },
      SubscribeOptions{config_.scan_max_age, 0.5});
  node_.subscribe<nav_state_t>(
      channels::kNavState, [this](const nav_state_t& m) { on_nav(m); },
      SubscribeOptions{config_.nav_max_age, 0.5});
  node_.add_timer(
      1.0 / config_.cuboid_rate, [this] { cuboid_cycle(); }, "cuboids");
}

void MapperService::on_nav(const nav_state_t& m) {
  mapper_.set_vehicle_position(Vec3(m.position[0], m.position[1], m.position[2]));
}

void MapperService::on_scan(const scan_world_t& m) {
  if (m.utime <= last_scan_utime_) {
    ++out_of_order_;
    node_.reject(channels::kScanWorld, "scan not newer than the last one");
    return;
  }
  last_scan_utime_ = m.utime;
  scan_.utime = m.utime;
  scan_.sensor_origin = Vec3(m.sensor_origin[0], m.sensor_origin[1], m.sensor_origin[2]);
  scan_.points.clear();
  scan_.free_ray_ends.clear();
  for (const auto& p : m.points) scan_.points.emplace_back(p[0], p[1], p[2]);
  for (const auto& p : m.free_ray_ends) scan_.free_ray_ends.emplace_back(p[0], p[1], p[2]);
  mapper_.add_scan(scan_);
  node_.publish(channels::kObstacleGrid,
                grid_message(mapper_.grid(), config_.mapper.grid.safety_margin,
                             config_.grid_crop_border, m.utime));
  node_.set_state("running");
}

void MapperService::cuboid_cycle() {
  const Utime now = node_.now();
  mapper_.update_cuboids(now);
  node_.publish(channels::kCuboids, cuboid_message(mapper_.obstacles(), now));
}

}  // namespace ofn::mapping
