// ofn_baseline: the offline time-optimal baseline of a course (scenario
// file), for the benchmark report's achieved / baseline ratio.
// Exit codes: 0 solved, 1 no feasible trajectory found, 2 bad input.

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>

#include "ofn/common/config.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/common/service_main.hpp"
#include "ofn/sim/time_optimal.hpp"

namespace {

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) {
    if (ch == '"' || ch == '\\') {
      out += '\\';
      out += ch;
    } else if (static_cast<unsigned char>(ch) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\u%04x", ch);
      out += buf;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

// JSON has no infinity: an unsolved course reports null.
std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  std::ostringstream o;
  o << std::setprecision(10) << v;
  return o.str();
}

void write_outputs(const std::string& dir, const ofn::Scenario& scenario,
                   const ofn::baseline::BaselineResult& r) {
  std::filesystem::create_directories(dir);
  const std::string json_path = dir + "/baseline.json";
  std::ofstream json(json_path);
  if (!json) throw std::runtime_error("cannot write " + json_path + ": " + std::strerror(errno));
  json << "{\n"
       << "  \"scenario\": " << json_string(scenario.name) << ",\n"
       << "  \"scenario_file\": " << json_string(scenario.file) << ",\n"
       << "  \"feasible\": " << (r.feasible ? "true" : "false") << ",\n"
       << "  \"reason\": " << json_string(r.reason) << ",\n"
       << "  \"baseline_time\": " << json_number(r.gate_to_gate) << ",\n"
       << "  \"lower_bound_time\": " << json_number(r.lower_bound) << ",\n"
       << "  \"path_length_lower_bound\": " << json_number(r.path_length_lower_bound) << ",\n"
       << "  \"total_time_lower_bound\": " << json_number(r.total_time_lower_bound) << ",\n"
       << "  \"total_path_length_lower_bound\": " << json_number(r.total_path_length_lower_bound)
       << ",\n"
       << "  \"worst_violation\": " << json_number(r.worst_violation) << ",\n"
       << "  \"worst_constraint\": " << json_string(r.worst_constraint) << ",\n"
       << "  \"route\": " << json_string(r.route) << ",\n"
       << "  \"initial_guess\": " << json_string(r.guess) << ",\n"
       << "  \"start_gate_time\": " << json_number(r.start_gate_time) << ",\n"
       << "  \"finish_gate_time\": " << json_number(r.finish_gate_time) << ",\n"
       << "  \"min_clearance\": " << json_number(r.min_clearance) << ",\n"
       << "  \"min_altitude\": " << json_number(r.min_altitude) << ",\n"
       << "  \"max_speed\": " << json_number(r.max_speed) << ",\n"
       << "  \"max_accel\": " << json_number(r.max_accel) << ",\n"
       << "  \"max_vertical_speed\": " << json_number(r.max_vertical_speed) << ",\n"
       << "  \"solve_time\": " << json_number(r.solve_time) << ",\n"
       << "  \"candidates\": [";
  for (size_t i = 0; i < r.candidates.size(); ++i) {
    const auto& c = r.candidates[i];
    json << (i ? ",\n" : "\n") << "    {\"guess\": " << json_string(c.guess)
         << ", \"route\": " << json_string(c.route)
         << ", \"feasible\": " << (c.feasible ? "true" : "false")
         << ", \"baseline_time\": " << json_number(c.gate_to_gate)
         << ", \"worst_violation\": " << json_number(c.worst_violation)
         << ", \"solve_time\": " << json_number(c.solve_time) << "}";
  }
  json << "\n  ]\n}\n";

  const std::string csv_path = dir + "/baseline_trajectory.csv";
  std::ofstream csv(csv_path);
  if (!csv) throw std::runtime_error("cannot write " + csv_path + ": " + std::strerror(errno));
  csv << "t [s],north [m],east [m],down [m],vn [m/s],ve [m/s],vd [m/s],an [m/s^2],ae [m/s^2],"
         "ad [m/s^2]\n"
      << std::setprecision(9);
  for (const auto& s : r.trajectory)
    csv << s.t << ',' << s.position.x() << ',' << s.position.y() << ',' << s.position.z() << ','
        << s.velocity.x() << ',' << s.velocity.y() << ',' << s.velocity.z() << ','
        << s.acceleration.x() << ',' << s.acceleration.y() << ',' << s.acceleration.z() << '\n';
}

void print_summary(const ofn::Scenario& scenario, const ofn::baseline::BaselineResult& r) {
  const double k = scenario.metres_per_unit;
  const std::string& u = scenario.display_unit;
  std::cout << std::fixed << std::setprecision(2);
  std::cout << "scenario " << scenario.name << ": "
            << (r.feasible ? "time-optimal baseline found" : "NO feasible trajectory") << '\n';
  if (!r.feasible) std::cout << "  reason: " << r.reason << '\n';
  std::cout << "  baseline (gate to gate): " << r.gate_to_gate << " s, route " << r.route
            << " (from the " << r.guess << " guess)\n"
            << "  lower bound: " << r.lower_bound
            << " s (path length >= " << r.path_length_lower_bound / k << ' ' << u << ")\n"
            << "  gates crossed at " << r.start_gate_time << " s and " << r.finish_gate_time
            << " s after the start (lower bound " << r.total_time_lower_bound
            << " s: path length from the start >= " << r.total_path_length_lower_bound / k << ' '
            << u << ")\n"
            << "  least clearance " << r.min_clearance / k << ' ' << u << " (R_s "
            << scenario.limits.clearance / k << "), lowest " << r.min_altitude / k << ' ' << u
            << " above ground\n"
            << "  largest speed " << r.max_speed / k << ' ' << u << "/s, acceleration "
            << r.max_accel / k << ' ' << u << "/s^2, vertical speed " << r.max_vertical_speed / k
            << ' ' << u << "/s\n"
            << std::setprecision(3) << "  worst violation " << 100.0 * r.worst_violation << " % ("
            << r.worst_constraint << ")\n"
            << std::setprecision(1) << "  computed in " << r.solve_time << " s\n";
}

}  // namespace

int main(int argc, char** argv) {
  ofn::CommandLine app{"ofn_baseline",
                       "ofn baseline: offline time-optimal gate-to-gate time of a course"};
  std::string scenario_path, out_dir;
  bool quiet = false;
  app.add_option("--scenario", scenario_path, "scenario file (YAML) with timing gates")->required();
  app.add_option("--out", out_dir, "folder for baseline.json and baseline_trajectory.csv");
  app.add_flag("--quiet", quiet, "no progress lines on stderr");
  ofn::baseline::BaselineSettings settings;
  app.add_option("--knot-spacing", settings.knot_spacing,
                 "s of trajectory per B-spline interval (finer: closer to the optimum, slower)")
      ->check(ofn::positive_number());
  app.add_option("--sample-spacing", settings.sample_spacing,
                 "s between the constraint samples of the programme")
      ->check(ofn::positive_number());
  app.add_option("--run-up-weight", settings.run_up_weight,
                 "cost of a second before the start gate against one between the gates "
                 "(1: fastest whole flight; near 0: least gate-to-gate time, any run-up)")
      ->check(ofn::number_between(0.0, 1.0));
  app.add_option("--max-solve-time", settings.max_solve_time, "s of computation per initial guess")
      ->check(ofn::positive_number());
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;
  ofn::Scenario scenario;
  try {
    scenario = ofn::load_scenario(scenario_path);
  } catch (const std::exception& e) {
    std::cerr << "ofn_baseline: " << e.what() << '\n';
    return 2;
  }
  if (!quiet) settings.progress = [](const std::string& line) { std::cerr << line << std::endl; };
  ofn::baseline::BaselineResult result;
  try {
    result = ofn::baseline::compute_time_optimal(scenario, settings);
  } catch (const std::invalid_argument& e) {
    std::cerr << "ofn_baseline: " << e.what() << '\n';
    return 2;
  }
  try {
    if (!out_dir.empty()) write_outputs(out_dir, scenario, result);
  } catch (const std::exception& e) {
    std::cerr << "ofn_baseline: " << e.what() << '\n';
    return 2;
  }
  print_summary(scenario, result);
  if (!result.feasible) {
    std::cerr << "ofn_baseline: no feasible trajectory: " << result.reason << '\n';
    return 1;
  }
  return 0;
}
