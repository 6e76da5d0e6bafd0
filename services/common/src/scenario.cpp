#include "ofn/common/scenario.hpp"

#include <algorithm>
#include <map>

#include "ofn/common/config.hpp"

namespace ofn {
namespace {

double positive(YamlReader& r, const std::string& key, double value) {
  if (!(value > 0)) r.fail(key, "must be > 0");
  return value;
}

/// One entry of the `obstacles` list; `index` is its 0-based position.
ObstacleSpec read_obstacle(YamlReader& o, size_t index, double metres_per_unit) {
  o.expect_only({"kind", "id", "center", "size", "radius", "height", "yaw_deg", "seed",
                 "appear_time", "disappear_time"});
  const double k = metres_per_unit;
  ObstacleSpec spec;
  const std::string kind = o.text("kind");
  if (kind == "box") {
    spec.kind = ObstacleSpec::Kind::kBox;
  } else if (kind == "cylinder") {
    spec.kind = ObstacleSpec::Kind::kCylinder;
  } else if (kind == "tree") {
    spec.kind = ObstacleSpec::Kind::kTree;
  } else {
    o.fail("kind", "expected box, cylinder or tree, got '" + kind + "'");
  }
  const bool is_box = spec.kind == ObstacleSpec::Kind::kBox;
  const bool is_cylinder = spec.kind == ObstacleSpec::Kind::kCylinder;
  const bool is_tree = spec.kind == ObstacleSpec::Kind::kTree;

  spec.id = o.integer("id", static_cast<int>(index) + 1);
  if (spec.id <= 0) o.fail("id", "must be > 0");

  const auto center = o.numbers("center", 2);
  spec.north = center[0] * k;
  spec.east = center[1] * k;

  // Each kind takes exactly its own shape fields, so that a field meant for
  // another kind is an error rather than silently ignored.
  if (is_cylinder) {
    if (o.has("size")) o.fail("size", "a cylinder takes radius, not size");
    if (!o.has("radius")) o.fail("radius", "required number is missing");
    const double radius = positive(o, "radius", o.number("radius"));
    spec.length = spec.width = 2.0 * radius * k;
  } else {
    if (o.has("radius"))
      o.fail("radius", "only a cylinder takes a radius; a " + kind + " takes size");
    const auto size = o.numbers("size", 2);
    spec.length = positive(o, "size", size[0]) * k;
    spec.width = positive(o, "size", size[1]) * k;
  }
  spec.height = positive(o, "height", o.number("height")) * k;

  if (!is_box && o.has("yaw_deg")) o.fail("yaw_deg", "only a box has a yaw");
  // Course yaw (from +x, positive to the right) is NED yaw (from north to east).
  spec.yaw = deg2rad(o.number_in("yaw_deg", 0.0, -360.0, 360.0));

  if (!is_tree && o.has("seed")) o.fail("seed", "only a tree has a seed");
  spec.seed = o.integer("seed", spec.id);

  if (o.has("appear_time")) spec.appear_time = o.number_in("appear_time", 0.0, 0.0, 1e6);
  if (o.has("disappear_time")) {
    spec.disappear_time = o.number_in("disappear_time", 0.0, 0.0, 1e6);
    const double appears = std::max(spec.appear_time, 0.0);
    if (spec.disappear_time <= appears)
      o.fail("disappear_time", "must be later than appear_time (the start if absent)");
  }
  o.finish();
  return spec;
}

void read_vehicle(YamlReader& v, Scenario& s) {
  VehicleVariation& out = s.vehicle;
  out.mass_scale = v.number_in("mass_scale", 1.0, 0.2, 5.0);
  const auto inertia = v.numbers_in("inertia_scale", {1.0, 1.0, 1.0}, 0.2, 5.0);
  out.inertia_scale = Vec3(inertia[0], inertia[1], inertia[2]);
  out.actuator_time_scale = v.number_in("actuator_time_scale", 1.0, 0.2, 10.0);
  YamlReader lim = v.child("actuator_limits");
  if (lim.has("collective_deg")) {
    const auto c = lim.numbers("collective_deg", 2);
    if (!(c[0] < c[1])) lim.fail("collective_deg", "expected [min, max] with min < max");
    out.collective_min = deg2rad(c[0]);
    out.collective_max = deg2rad(c[1]);
  }
  auto optional_angle = [&](const char* key, double hi, std::optional<double>& dst) {
    if (lim.has(key)) dst = deg2rad(lim.number_in(key, 0.0, 0.01, hi));
  };
  optional_angle("cyclic_deg", 45.0, out.cyclic_limit);
  optional_angle("pedal_deg", 60.0, out.pedal_limit);
  optional_angle("collective_rate_deg_s", 10000.0, out.collective_rate);
  optional_angle("cyclic_rate_deg_s", 10000.0, out.cyclic_rate);
  optional_angle("pedal_rate_deg_s", 10000.0, out.pedal_rate);
  lim.finish();
  v.finish();
}

void read_disturbances(YamlReader& d, Scenario& s) {
  const double k = s.metres_per_unit;
  Disturbances& out = s.disturbances;
  constexpr double kKnot = 1852.0 / 3600.0;
  // MIL-F-8785C: wind speed at 20 ft for light, moderate and severe turbulence.
  const std::string level = d.text("turbulence", "none");
  if (level == "none") {
    out.turbulence.wind_at_20ft = 0;
  } else if (level == "light") {
    out.turbulence.wind_at_20ft = 15 * kKnot;
  } else if (level == "moderate") {
    out.turbulence.wind_at_20ft = 30 * kKnot;
  } else if (level == "severe") {
    out.turbulence.wind_at_20ft = 45 * kKnot;
  } else {
    d.fail("turbulence", "expected none, light, moderate or severe, got '" + level + "'");
  }
  auto non_negative_vec = [&](const char* key, double scale) -> Vec3 {
    const auto v = d.numbers(key, 3);
    for (double x : v)
      if (!(x >= 0)) d.fail(key, "every component must be >= 0");
    return Vec3(v[0], v[1], v[2]) * scale;
  };
  if (d.has("turbulence_sigma")) {
    if (level != "none") d.fail("turbulence_sigma", "give a turbulence level or sigma, not both");
    out.turbulence.sigma = non_negative_vec("turbulence_sigma", k);
  }
  if (d.has("turbulence_scale")) {
    const Vec3 scale = non_negative_vec("turbulence_scale", k);
    if (!(scale.minCoeff() > 0)) d.fail("turbulence_scale", "every scale length must be > 0");
    out.turbulence.scale_length = scale;
  }
  YamlReader nav = d.child("nav_noise");
  out.nav.position_sigma = nav.number_in("position", 0.0, 0.0, 1e3) * k;
  out.nav.velocity_sigma = nav.number_in("velocity", 0.0, 0.0, 1e3) * k;
  out.nav.attitude_sigma = deg2rad(nav.number_in("attitude_deg", 0.0, 0.0, 30.0));
  out.nav.rate_sigma = deg2rad(nav.number_in("rate_deg_s", 0.0, 0.0, 100.0));
  out.nav.latency = nav.number_in("latency", 0.0, 0.0, 1.0);
  nav.finish();
  const int seed = d.integer("seed", 1);
  if (seed < 0) d.fail("seed", "expected a whole number >= 0");
  out.seed = static_cast<uint32_t>(seed);
  d.finish();
}

}  // namespace

Scenario load_scenario(const std::string& path) {
  YamlReader root = YamlReader::load_file(path);
  root.expect_only({"name", "description", "units", "start", "waypoints", "capture_radius",
                    "cruise_speed", "limits", "gates", "environment", "obstacles", "max_time",
                    "vehicle", "disturbances"});
  Scenario s;
  s.file = path;
  s.name = root.text("name");
  s.description = root.text("description", "");
  s.display_unit = root.text("units");
  if (s.display_unit == "ft") {
    s.metres_per_unit = kMetresPerFoot;
  } else if (s.display_unit == "m") {
    s.metres_per_unit = 1.0;
  } else {
    root.fail("units", "expected 'ft' or 'm', got '" + s.display_unit + "'");
  }
  const double k = s.metres_per_unit;
  auto course_point = [&](YamlReader& r, const std::string& key) {
    const auto v = r.numbers(key, 3);
    if (v[2] < 0) r.fail(key, "height h must be >= 0 (course frame is x, y, h)");
    return course_to_ned(Vec3(v[0], v[1], v[2]) * k);
  };

  YamlReader start = root.child("start");
  s.start_position = course_point(start, "position");
  s.start_heading = deg2rad(start.number_in("heading_deg", 0.0, -360.0, 360.0));
  const double start_speed = start.number_in("speed", 0.0, 0.0, 1e3) * k;
  s.start_velocity = Vec3(std::cos(s.start_heading), std::sin(s.start_heading), 0.0) * start_speed;
  start.finish();

  YamlReader limits = root.child("limits");
  s.limits.max_speed = limits.number_in("max_speed", 0.0, 1e-6, 1e3) * k;
  s.limits.max_accel = limits.number_in("max_accel", 0.0, 1e-6, 1e3) * k;
  s.limits.max_vertical_speed = limits.number_in("max_vertical_speed", 0.0, 1e-6, 1e3) * k;
  s.limits.min_forward_speed = limits.number_in("min_forward_speed", 0.0, 0.0, 1e3) * k;
  s.limits.clearance = limits.number_in("clearance", 0.0, 0.0, 1e4) * k;
  s.limits.sensor_range = limits.number_in("sensor_range", 0.0, 0.0, 1e5) * k;
  for (const char* key : {"max_speed", "max_accel", "max_vertical_speed"})
    if (!limits.has(key)) limits.fail(key, "required number is missing");
  limits.finish();

  s.cruise_speed = root.number_in("cruise_speed", s.limits.max_speed / k, 1e-6, 1e3) * k;
  if (s.cruise_speed > s.limits.max_speed * (1 + 1e-9))
    root.fail("cruise_speed", "must not exceed limits.max_speed");

  const double default_capture = root.number_in("capture_radius", 10.0 / k, 1e-6, 1e5) * k;
  auto waypoints = root.children("waypoints");
  if (waypoints.empty()) root.fail("waypoints", "expected a list of at least one waypoint");
  for (auto& w : waypoints) {
    Waypoint wp;
    wp.position = course_point(w, "position");
    wp.capture_radius = w.number_in("capture_radius", default_capture / k, 1e-6, 1e5) * k;
    w.finish();
    s.waypoints.push_back(wp);
  }

  YamlReader course = root.child("gates");
  if (course.has("start_x")) s.start_gate = course.number("start_x") * k;
  if (course.has("finish_x")) s.finish_gate = course.number("finish_x") * k;
  if (s.start_gate && s.finish_gate && *s.finish_gate <= *s.start_gate)
    course.fail("finish_x", "must lie beyond start_x");
  course.finish();

  YamlReader env = root.child("environment");
  const auto wind = env.numbers("wind", {0.0, 0.0, 0.0});
  // Wind is given in the course frame too (x, y, h-rate); NED flips the last.
  s.wind = course_to_ned(Vec3(wind[0], wind[1], wind[2]) * k);
  s.ground_altitude = env.number_in("ground_altitude", 0.0, -1e5, 1e5) * k;
  env.finish();

  auto obstacles = root.children("obstacles");
  std::map<int, size_t> index_of_id;
  for (size_t i = 0; i < obstacles.size(); ++i) {
    ObstacleSpec spec = read_obstacle(obstacles[i], i, k);
    const auto [it, inserted] = index_of_id.emplace(spec.id, i);
    if (!inserted)
      obstacles[i].fail("id", "duplicate id " + std::to_string(spec.id) + " (also obstacles[" +
                                  std::to_string(it->second) + "])");
    s.obstacles.push_back(spec);
  }

  s.max_time = root.number_in("max_time", 600.0, 1.0, 1e6);
  YamlReader vehicle = root.child("vehicle");
  read_vehicle(vehicle, s);
  YamlReader disturbances = root.child("disturbances");
  read_disturbances(disturbances, s);
  root.finish();
  return s;
}

}  // namespace ofn
