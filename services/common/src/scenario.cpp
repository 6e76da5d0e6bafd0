#include "ofn/common/scenario.hpp"

#include "ofn/common/config.hpp"

namespace ofn {

Scenario load_scenario(const std::string& path) {
  YamlReader root = YamlReader::load_file(path);
  root.expect_only({"name", "description", "units", "start", "waypoints", "capture_radius",
                    "cruise_speed", "limits", "gates", "environment", "max_time"});
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
  env.finish();

  s.max_time = root.number_in("max_time", 600.0, 1.0, 1e6);
  root.finish();
  return s;
}

}  // namespace ofn
