#include "ofn/tools/flight_report.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <stdexcept>

#include <lcm/lcm-cpp.hpp>

#include "ofn/actuator_cmd_t.hpp"
#include "ofn/bus_auth/trailer.hpp"
#include "ofn/common/channels.hpp"
#include "ofn/common/clock.hpp"
#include "ofn/common/mission_plan.hpp"
#include "ofn/common/ref_traj_sample.hpp"
#include "ofn/common/validate.hpp"
#include "ofn/control_status_t.hpp"
#include "ofn/cuboid_list_t.hpp"
#include "ofn/global_path_t.hpp"
#include "ofn/heartbeat_t.hpp"
#include "ofn/mission_t.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/obstacle_grid_t.hpp"
#include "ofn/ref_traj_t.hpp"
#include "ofn/scan_world_t.hpp"
#include "ofn/solver_stats_t.hpp"
#include "ofn/world/world.hpp"

namespace ofn::report {
namespace {

/// The q-quantile (0..1, nearest rank) of the values; none when empty.
std::optional<double> percentile(std::vector<double> values, double q) {
  if (values.empty()) return std::nullopt;
  std::sort(values.begin(), values.end());
  const size_t i = std::min(
      values.size() - 1,
      static_cast<size_t>(std::ceil(q * values.size()) > 0 ? std::ceil(q * values.size()) - 1 : 0));
  return values[i];
}

// A message alone, or with the trailer of an authenticated bus.
template <class Msg>
bool decode(const lcm::LogEvent& e, Msg& out) {
  return e.datalen >= 0 && bus_auth::decode_payload(out, e.data, static_cast<size_t>(e.datalen));
}

// A text field of a CSV row, quoted when it holds a separator, a quote or a
// line break (a heartbeat's service name comes from the bus, whoever sent it).
std::string csv_text(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + "\"";
}

std::ofstream open_csv(const std::filesystem::path& path, const std::string& header) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error("cannot write " + path.string());
  f << std::setprecision(10) << header << "\n";
  return f;
}

const char* kind_name(ObstacleSpec::Kind k) {
  switch (k) {
    case ObstacleSpec::Kind::kBox:
      return "box";
    case ObstacleSpec::Kind::kCylinder:
      return "cylinder";
    case ObstacleSpec::Kind::kTree:
      return "tree";
  }
  return "box";
}

std::string json_number(std::optional<double> v) {
  if (!v || !std::isfinite(*v)) return "null";
  std::ostringstream s;
  s << std::setprecision(10) << *v;
  return s.str();
}

}  // namespace

ReportResult write_flight_report(const std::string& log_path, const std::string& out_dir,
                                 const std::optional<Scenario>& scenario,
                                 const PseudoControlBound& pseudo_control_bound) {
  lcm::LogFile log(log_path, "r");
  if (!log.good()) throw std::invalid_argument("cannot read LCM log " + log_path);
  namespace fs = std::filesystem;
  const fs::path out(out_dir);
  fs::create_directories(out);

  ReportResult result;
  std::vector<NavSample> nav;
  std::vector<StatusSample> status;
  std::optional<mission_t> mission;
  std::optional<Utime> t0;
  auto rel = [&](Utime t) { return to_seconds(t - *t0); };

  auto nav_csv =
      open_csv(out / "nav_state.csv", "t,north,east,down,vn,ve,vd,an,ae,ad,roll,pitch,yaw,p,q,r");
  auto status_csv = open_csv(out / "control_status.csv",
                             "t,mode,mission_id,active_waypoint,ref_n,ref_e,ref_d,ref_vn,ref_ve,"
                             "ref_vd,ref_an,ref_ae,ref_ad,cmd_an,cmd_ae,cmd_ad,err_n,err_e,err_d,"
                             "yaw_ref");
  auto cmd_csv = open_csv(out / "actuator_cmd.csv", "t,collective,lon_cyclic,lat_cyclic,pedal");
  auto hb_csv = open_csv(out / "heartbeats.csv",
                         "t,service,state,received,rejected,late,loop_time_mean,loop_time_max,"
                         "cpu_fraction,unauthenticated");
  // Every scan point of a long flight would make a plot unreadable and a
  // file of hundreds of MB: keep every n-th point, up to a budget.
  constexpr size_t kScanPointStride = 7;
  constexpr size_t kMaxScanPoints = 300000;
  auto scan_csv = open_csv(out / "scan_points.csv", "t,north,east,down");
  size_t scan_points_seen = 0, scan_points_written = 0;
  std::optional<cuboid_list_t> last_cuboids;
  // Planning: every global path, every n-th avoidance trajectory (a 10 Hz
  // optimiser would otherwise paint a solid band), every solver report.
  constexpr int kRefTrajStride = 5;
  auto path_csv = open_csv(out / "global_path.csv", "t,seq,status,cost,north,east,down");
  auto ref_csv = open_csv(out / "ref_traj.csv", "t,seq,mode,sample_t,north,east,down");
  auto stats_csv = open_csv(out / "solver_stats.csv",
                            "t,status,iterations,solve_time,max_violation,cost,warm_started");
  int path_seq = 0, ref_seq = 0, ref_seen = 0;
  std::vector<double> solve_times;
  std::map<int, int> solver_status_count;
  std::vector<TimeSpan> recovery;
  // Scan-to-plan latency: every map's stamp, and every step that planned.
  std::vector<double> map_stamps;
  std::vector<PlanStep> plan_steps;
  auto row = [](std::ofstream& f, std::initializer_list<Vec3> vs) {
    for (const auto& v : vs) f << "," << v.x() << "," << v.y() << "," << v.z();
  };

  // Events before the first navigation sample have no time base yet; keep
  // them until it arrives.
  std::vector<lcm::LogEvent> held;
  std::vector<std::vector<uint8_t>> held_data;
  auto handle = [&](const std::string& channel, const lcm::LogEvent& e) {
    if (channel == channels::kNavState) {
      nav_state_t m{};
      if (!decode(e, m)) return false;
      NavSample s;
      s.t = rel(m.utime);
      s.position = to_vec3(m.position);
      s.velocity = to_vec3(m.velocity);
      s.acceleration = to_vec3(m.acceleration);
      s.euler = to_vec3(m.euler);
      s.body_rates = to_vec3(m.body_rates);
      nav.push_back(s);
      nav_csv << s.t;
      row(nav_csv, {s.position, s.velocity, s.acceleration, s.euler, s.body_rates});
      nav_csv << "\n";
    } else if (channel == channels::kControlStatus) {
      control_status_t m{};
      if (!decode(e, m)) return false;
      StatusSample s;
      s.t = rel(m.utime);
      s.mode = m.mode;
      s.mission_id = m.mission_id;
      s.active_waypoint = m.active_waypoint;
      s.ref_position = to_vec3(m.ref_position);
      s.ref_velocity = to_vec3(m.ref_velocity);
      s.ref_acceleration = to_vec3(m.ref_acceleration);
      s.commanded_accel = to_vec3(m.commanded_acceleration);
      s.position_error = to_vec3(m.position_error);
      s.yaw_reference = m.yaw_reference;
      status.push_back(s);
      status_csv << s.t << "," << s.mode << "," << s.mission_id << "," << s.active_waypoint;
      row(status_csv, {s.ref_position, s.ref_velocity, s.ref_acceleration, s.commanded_accel,
                       s.position_error});
      status_csv << "," << s.yaw_reference << "\n";
    } else if (channel == channels::kActuatorCmd) {
      actuator_cmd_t m{};
      if (!decode(e, m)) return false;
      cmd_csv << rel(m.utime) << "," << m.collective << "," << m.lon_cyclic << "," << m.lat_cyclic
              << "," << m.pedal << "\n";
    } else if (channel == channels::kScanWorld) {
      scan_world_t m{};
      if (!decode(e, m)) return false;
      for (const auto& p : m.points) {
        if (scan_points_seen++ % kScanPointStride != 0 || scan_points_written >= kMaxScanPoints)
          continue;
        ++scan_points_written;
        scan_csv << rel(m.utime) << "," << p[0] << "," << p[1] << "," << p[2] << "\n";
      }
    } else if (channel == channels::kCuboids) {
      cuboid_list_t m{};
      if (!decode(e, m)) return false;
      last_cuboids = std::move(m);
    } else if (channel == channels::kGlobalPath) {
      global_path_t m{};
      if (!decode(e, m)) return false;
      for (const auto& p : m.points)
        path_csv << rel(m.utime) << "," << path_seq << "," << static_cast<int>(m.status) << ","
                 << m.cost << "," << p[0] << "," << p[1] << "," << p[2] << "\n";
      ++path_seq;
    } else if (channel == channels::kRefTraj) {
      ref_traj_t m{};
      if (!decode(e, m)) return false;
      // A plan sent as its spline alone is tabled as its receivers sample it.
      if (validate(m).empty()) expand_ref_traj(m);
      if (m.mode != ref_traj_t::NOMINAL && ref_seen++ % kRefTrajStride == 0) {
        for (size_t i = 0; i < m.sample_time.size(); ++i)
          ref_csv << rel(m.utime) << "," << ref_seq << "," << static_cast<int>(m.mode) << ","
                  << rel(m.t0_utime) + m.sample_time[i] << "," << m.position[i][0] << ","
                  << m.position[i][1] << "," << m.position[i][2] << "\n";
        ++ref_seq;
      }
    } else if (channel == channels::kSolverStats) {
      solver_stats_t m{};
      if (!decode(e, m)) return false;
      stats_csv << rel(m.utime) << "," << static_cast<int>(m.status) << "," << m.iterations << ","
                << m.solve_time << "," << m.max_constraint_violation << "," << m.cost << ","
                << (m.warm_started ? 1 : 0) << "\n";
      if (m.status != solver_stats_t::NOT_RUN) {
        ++solver_status_count[m.status];
        solve_times.push_back(m.solve_time);
      }
      // Steps that published a trajectory (a deferral leaves guidance on).
      if (m.status != solver_stats_t::NOT_RUN && m.status != solver_stats_t::DEFERRED &&
          m.map_utime > 0)
        plan_steps.push_back({rel(m.utime), rel(m.map_utime)});
      // The dead-end recovery's steps, joined into spans (the optimiser
      // reports at 5-20 Hz; a gap of a second ends a span).
      const bool recovering = m.status == solver_stats_t::LOOKING_AROUND ||
                              m.status == solver_stats_t::NO_ROUTE ||
                              m.message.rfind("escaping", 0) == 0;
      if (recovering) {
        const double t = rel(m.utime);
        if (!recovery.empty() && t - recovery.back().end <= 1.0)
          recovery.back().end = t;
        else
          recovery.push_back({t, t});
      }
    } else if (channel == channels::kObstacleGrid) {
      obstacle_grid_t m{};
      if (!decode(e, m)) return false;
      map_stamps.push_back(rel(m.utime));
    } else if (channel == channels::kMission) {
      mission_t m{};
      if (!decode(e, m)) return false;
      mission = m;
    } else if (channel.rfind(channels::kHeartbeatPrefix, 0) == 0) {
      heartbeat_t m{};
      if (!decode(e, m)) return false;
      hb_csv << rel(m.utime) << "," << csv_text(m.service) << "," << csv_text(m.state) << ","
             << m.received << "," << m.rejected << "," << m.late << "," << m.loop_time_mean << ","
             << m.loop_time_max << "," << m.cpu_fraction << "," << m.unauthenticated << "\n";
    }
    return true;
  };

  while (const lcm::LogEvent* e = log.readNextEvent()) {
    ++result.events;
    if (!t0) {
      if (e->channel == channels::kNavState) {
        nav_state_t m{};
        if (decode(*e, m)) t0 = m.utime;
      }
      if (!t0) {
        held.push_back(*e);
        held_data.emplace_back(static_cast<const uint8_t*>(e->data),
                               static_cast<const uint8_t*>(e->data) + e->datalen);
        held.back().data = held_data.back().data();
        continue;
      }
      for (size_t i = 0; i < held.size(); ++i) {
        held[i].data = held_data[i].data();
        if (!handle(held[i].channel, held[i])) ++result.undecodable;
      }
      held.clear();
    }
    if (!handle(e->channel, *e)) ++result.undecodable;
  }
  // Bad input (exit code 2), like an unreadable log.
  if (nav.empty()) throw std::invalid_argument(log_path + ": no NAV_STATE messages in the log");
  // A multi-process log holds messages in arrival order.
  std::sort(map_stamps.begin(), map_stamps.end());
  std::sort(plan_steps.begin(), plan_steps.end(),
            [](const PlanStep& a, const PlanStep& b) { return a.published < b.published; });
  const std::vector<double> scan_to_plan = scan_to_plan_latencies(map_stamps, plan_steps);

  Limits limits;
  if (mission) {
    limits = limits_from(mission->limits);
    auto wp_csv = open_csv(out / "waypoints.csv", "index,north,east,down,capture_radius");
    for (size_t i = 0; i < mission->waypoints.size(); ++i) {
      const auto& w = mission->waypoints[i];
      wp_csv << i << "," << w.position[0] << "," << w.position[1] << "," << w.position[2] << ","
             << w.capture_radius << "\n";
    }
  } else {
    open_csv(out / "waypoints.csv", "index,north,east,down,capture_radius");
  }
  {
    // The obstacle database as it stood at the end of the flight.
    auto cuboid_csv = open_csv(out / "cuboids.csv",
                               "t,id,min_n,min_e,min_d,max_n,max_e,max_d,top_observed,confidence");
    if (last_cuboids)
      for (const auto& c : last_cuboids->cuboids)
        cuboid_csv << rel(last_cuboids->utime) << "," << c.id << "," << c.min_corner[0] << ","
                   << c.min_corner[1] << "," << c.min_corner[2] << "," << c.max_corner[0] << ","
                   << c.max_corner[1] << "," << c.max_corner[2] << "," << (c.top_observed ? 1 : 0)
                   << "," << c.confidence << "\n";
  }
  // True clearance: distance from the flown path to the real surfaces, the
  // obstacles present at that time and the ground, over the whole flight.
  std::optional<Clearance> clearance;
  if (scenario)
    clearance = least_clearance(nav, world::World(scenario->obstacles, scenario->ground_altitude));
  const std::optional<double> min_clearance =
      clearance ? std::optional<double>(clearance->distance) : std::nullopt;
  result.min_clearance = min_clearance;
  const auto start_gate = scenario ? scenario->start_gate : std::nullopt;
  const auto finish_gate = scenario ? scenario->finish_gate : std::nullopt;
  result.summary = analyse_flight(nav, status, limits, start_gate, finish_gate, recovery);
  const FlightSummary& s = result.summary;

  const std::string unit = scenario ? scenario->display_unit : "m";
  const double k = scenario ? scenario->metres_per_unit : 1.0;
  result.verdict = judge_flight(s, limits, pseudo_control_bound, min_clearance,
                                finish_gate.has_value(), DisplayUnit{unit, k});
  const std::string name = scenario ? scenario->name : (mission ? mission->name : "flight");

  std::ofstream json(out / "summary.json");
  json << std::setprecision(10) << "{\n"
       << "  \"scenario\": \"" << name << "\",\n"
       << "  \"log\": \"" << log_path << "\",\n"
       << "  \"display_unit\": \"" << unit << "\",\n"
       << "  \"metres_per_unit\": " << k << ",\n"
       << "  \"limits\": {\"max_speed\": " << limits.max_speed
       << ", \"max_accel\": " << limits.max_accel
       << ", \"max_vertical_speed\": " << limits.max_vertical_speed << "},\n"
       << "  \"gates\": {\"start_x\": " << json_number(start_gate)
       << ", \"finish_x\": " << json_number(finish_gate) << "},\n"
       << "  \"gate_start_t\": " << json_number(s.gate_start_time) << ",\n"
       << "  \"gate_finish_t\": " << json_number(s.gate_finish_time) << ",\n"
       << "  \"gate_to_gate\": " << json_number(s.gate_to_gate) << ",\n"
       << "  \"reached_last_waypoint\": " << (s.reached_last_waypoint ? "true" : "false") << ",\n"
       << "  \"crossed_finish\": " << (s.crossed_finish ? "true" : "false") << ",\n"
       << "  \"duration\": " << s.duration << ",\n"
       << "  \"max_speed\": " << s.max_speed << ",\n"
       << "  \"max_vertical_speed\": " << s.max_vertical_speed << ",\n"
       << "  \"min_forward_speed\": " << s.min_forward_speed << ",\n"
       << "  \"max_commanded_accel\": " << s.max_commanded_accel << ",\n"
       << "  \"max_commanded_accel_fraction\": " << s.max_commanded_accel_fraction << ",\n"
       << "  \"max_pseudo_control\": " << s.max_pseudo_control << ",\n"
       << "  \"max_pseudo_control_horizontal\": " << s.max_pseudo_control_horizontal << ",\n"
       << "  \"max_pseudo_control_vertical\": " << s.max_pseudo_control_vertical << ",\n"
       << "  \"pseudo_control_bound\": {\"horizontal\": " << pseudo_control_bound.horizontal
       << ", \"vertical\": " << pseudo_control_bound.vertical << "},\n"
       << "  \"max_ref_position_jump\": " << s.max_ref_position_jump << ",\n"
       << "  \"max_ref_position_jump_t\": " << json_number(s.max_ref_position_jump_t) << ",\n"
       << "  \"max_ref_velocity_jump\": " << s.max_ref_velocity_jump << ",\n"
       << "  \"final_max_speed\": " << json_number(s.final_max_speed) << ",\n"
       << "  \"tracking_rms\": " << s.tracking_rms << ",\n"
       << "  \"tracking_max\": " << s.tracking_max << ",\n"
       << "  \"min_clearance\": " << json_number(min_clearance) << ",\n"
       << "  \"min_clearance_t\": " << (clearance ? json_number(clearance->t) : "null") << ",\n"
       << "  \"min_clearance_surface\": "
       << (clearance ? (clearance->to_ground ? "\"ground\"" : "\"obstacle\"") : "null") << ",\n"
       << "  \"clearance_required\": " << limits.clearance << ",\n"
       << "  \"rh_steps\": " << solve_times.size() << ",\n"
       << "  \"rh_solve_time_median\": " << json_number(percentile(solve_times, 0.5)) << ",\n"
       << "  \"rh_solve_time_p99\": " << json_number(percentile(solve_times, 0.99)) << ",\n"
       << "  \"rh_solve_time_max\": " << json_number(percentile(solve_times, 1.0)) << ",\n"
       << "  \"rh_kept_previous\": " << solver_status_count[solver_stats_t::KEPT_PREVIOUS] << ",\n"
       << "  \"rh_braking\": " << solver_status_count[solver_stats_t::BRAKING] << ",\n"
       << "  \"rh_deferred\": " << solver_status_count[solver_stats_t::DEFERRED] << ",\n"
       << "  \"rh_looking_around\": " << solver_status_count[solver_stats_t::LOOKING_AROUND]
       << ",\n"
       << "  \"rh_no_route\": " << solver_status_count[solver_stats_t::NO_ROUTE] << ",\n"
       << "  \"scan_to_plan_scans\": " << scan_to_plan.size() << ",\n"
       << "  \"scan_to_plan_median\": " << json_number(percentile(scan_to_plan, 0.5)) << ",\n"
       << "  \"scan_to_plan_p99\": " << json_number(percentile(scan_to_plan, 0.99)) << ",\n"
       << "  \"scan_to_plan_max\": " << json_number(percentile(scan_to_plan, 1.0)) << ",\n"
       << "  \"recovery_time\": " << s.recovery_time << ",\n"
       << "  \"outcome\": \"" << to_string(result.verdict.outcome) << "\",\n"
       << "  \"success\": " << (result.verdict.success ? "true" : "false") << ",\n"
       << "  \"failures\": [";
  for (size_t i = 0; i < result.verdict.failures.size(); ++i)
    json << (i ? ", " : "") << "\"" << result.verdict.failures[i] << "\"";
  json << "],\n"
       << "  \"obstacles\": [";
  if (scenario) {
    // Metres, like every other length in this file (the plot scales them).
    const auto& obs = scenario->obstacles;
    for (size_t i = 0; i < obs.size(); ++i) {
      const auto& o = obs[i];
      json << (i ? ",\n    " : "\n    ") << "{\"id\": " << o.id << ", \"kind\": \""
           << kind_name(o.kind) << "\", \"center\": [" << o.north << ", " << o.east
           << "], \"size\": [" << o.length << ", " << o.width << "], \"height\": " << o.height
           << ", \"yaw\": " << o.yaw << ", \"appear_time\": " << o.appear_time
           << ", \"disappear_time\": " << o.disappear_time << "}";
    }
    if (!obs.empty()) json << "\n  ";
  }
  json << "]\n}\n";

  std::ostringstream t;
  t << std::fixed << std::setprecision(2);
  t << "Flight '" << name << "' (" << result.events << " logged messages, " << s.duration
    << " s of navigation data)\n";
  t << "  result            : "
    << (s.reached_last_waypoint ? "reached the last waypoint" : "did NOT reach the last waypoint");
  if (finish_gate)
    t << (s.crossed_finish ? ", crossed the finish gate" : ", did NOT cross the finish gate");
  t << "\n";
  t << "  outcome           : " << to_string(result.verdict.outcome);
  switch (result.verdict.outcome) {
    case Outcome::kSuccess:
      t << " (goal reached, no rule broken)";
      break;
    case Outcome::kSafeStop:
      t << " (goal not reached, no rule broken, hovering at the end: at most "
        << s.final_max_speed.value_or(0.0) / k << " " << unit << "/s over the last " << kHoverWindow
        << " s)";
      break;
    case Outcome::kFailure:
      for (const auto& f : result.verdict.failures) t << "\n                      " << f;
      break;
  }
  t << "\n";
  if (s.gate_to_gate)
    t << "  gate-to-gate time : " << *s.gate_to_gate << " s (x = " << *start_gate / k << " -> "
      << *finish_gate / k << " " << unit << ")\n";
  else if (start_gate || finish_gate)
    t << "  gate-to-gate time : n/a (a gate was not crossed)\n";
  t << "  max speed         : " << s.max_speed / k << " " << unit << "/s (limit "
    << limits.max_speed / k << ")\n";
  t << "  max reference acc : " << s.max_commanded_accel / k << " " << unit
    << "/s^2 = " << std::setprecision(0) << 100.0 * s.max_commanded_accel_fraction
    << std::setprecision(2) << " % of the " << limits.max_accel / k << " " << unit
    << "/s^2 limit (planned)\n";
  t << "  max pseudo-control: " << s.max_pseudo_control / k << " " << unit
    << "/s^2 (command plus feedback corrections); horizontal "
    << s.max_pseudo_control_horizontal / k << ", vertical " << s.max_pseudo_control_vertical / k
    << " (bounds " << pseudo_control_bound.horizontal / k << ", "
    << pseudo_control_bound.vertical / k << ")\n";
  t << "  reference jump    : " << s.max_ref_position_jump / k << " " << unit << ", "
    << s.max_ref_velocity_jump / k << " " << unit << "/s between samples (largest; position bound "
    << kMaxReferenceJump / k << " " << unit << ")\n";
  t << "  tracking error    : RMS " << s.tracking_rms / k << " " << unit << ", max "
    << s.tracking_max / k << " " << unit << "\n";
  if (clearance)
    t << "  least clearance   : " << clearance->distance / k << " " << unit
      << (clearance->to_ground ? " to the ground" : " to a real obstacle")
      << " at t = " << clearance->t << " s (required " << limits.clearance / k << ")\n";
  if (last_cuboids)
    t << "  obstacle database : " << last_cuboids->num_cuboids << " cuboids at the end, "
      << scan_points_seen << " LIDAR points mapped\n";
  if (!solve_times.empty()) {
    t << "  RH optimiser      : " << solve_times.size() << " steps, solve time median "
      << std::setprecision(1) << 1e3 * *percentile(solve_times, 0.5) << " ms, p99 "
      << 1e3 * *percentile(solve_times, 0.99) << " ms, max " << 1e3 * *percentile(solve_times, 1.0)
      << std::setprecision(2) << " ms; kept previous "
      << solver_status_count[solver_stats_t::KEPT_PREVIOUS] << ", braking "
      << solver_status_count[solver_stats_t::BRAKING] << ", deferred "
      << solver_status_count[solver_stats_t::DEFERRED] << ", looking around "
      << solver_status_count[solver_stats_t::LOOKING_AROUND] << ", no route "
      << solver_status_count[solver_stats_t::NO_ROUTE] << "; " << std::setprecision(1)
      << s.recovery_time << " s in dead-end recovery\n"
      << std::setprecision(2);
  } else {
    t << "  RH optimiser      : never engaged (nominal waypoint guidance throughout)\n";
  }
  if (!scan_to_plan.empty())
    t << "  scan to plan      : median " << std::setprecision(0)
      << 1e3 * *percentile(scan_to_plan, 0.5) << " ms, p99 "
      << 1e3 * *percentile(scan_to_plan, 0.99) << " ms, max "
      << 1e3 * *percentile(scan_to_plan, 1.0) << " ms over " << scan_to_plan.size()
      << " scans while avoiding (a scan's stamp to the first RH step on a map holding it)\n"
      << std::setprecision(2);
  if (path_seq > 0) t << "  global planner    : " << path_seq << " paths published\n";
  if (result.undecodable)
    t << "  warning           : " << result.undecodable << " undecodable messages skipped\n";
  t << "  files             : " << out.string() << "/{nav_state,control_status,actuator_cmd,"
    << "heartbeats,waypoints,scan_points,cuboids,global_path,ref_traj,solver_stats}.csv, "
    << "summary.json\n";
  result.text = t.str();
  std::ofstream(out / "summary.txt") << result.text;
  return result;
}

}  // namespace ofn::report
