// Tracking sweep: RMS and largest position error of the trajectory follower,
// adaptive and non-adaptive, over a grid of airframe errors (mass, inertia,
// actuator and rotor time constants) and crosswinds with Dryden turbulence,
// on the no-obstacle course flown in-process, with the gains, adaptation and
// guidance of a controller config file (by default the repository's). Writes
// a Markdown table and a CSV (for plot_tracking_sweep.py) into the output
// folder.

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "ofn/common/command_line.hpp"
#include "ofn/common/config.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/controller/controller_service.hpp"
#include "ofn/sim/tracking_flight.hpp"

namespace {

struct AirframeError {
  const char* name;
  double inertia_scale;
  double time_scale;
};

}  // namespace

int main(int argc, char** argv) {
  ofn::CommandLine app{"ofn_tracking_sweep",
                       "ofn tracking sweep: adaptive vs non-adaptive tracking error"};
  std::string scenario_path = std::string(OFN_SOURCE_DIR) + "/sim/scenarios/open.yaml";
  std::string out_dir = std::string(OFN_SOURCE_DIR) + "/results/bench";
  std::string config_path = std::string(OFN_SOURCE_DIR) + "/config/controller.yaml";
  double duration = 240;
  std::string turbulence = "light";
  app.add_option("--scenario", scenario_path,
                 "course to fly (its own wind and errors are replaced)")
      ->check(CLI::ExistingFile);
  app.add_option("--config", config_path,
                 "controller config: gains, adaptation and guidance of the adaptive case; the "
                 "non-adaptive case is the same with adaptation off")
      ->check(CLI::ExistingFile);
  app.add_option("--out", out_dir, "folder for tracking_sweep.md and tracking_sweep.csv");
  app.add_option("--duration", duration, "s of flight per case (the route is flown back and forth)")
      ->check(ofn::positive_number());
  app.add_option("--turbulence", turbulence, "turbulence on every windy case")
      ->check(CLI::IsMember({"none", "light", "moderate", "severe"}));
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;

  ofn::Scenario base;
  ofn::sim::TrackingSetup tuned;
  try {
    base = ofn::load_scenario(scenario_path);
    auto reader = ofn::YamlReader::load_file(config_path);
    const auto controller = ofn::control::load_controller_config(reader);
    tuned.gains = controller.gains;
    tuned.adaptive = controller.adaptive;
    tuned.guidance = controller.guidance;
    tuned.nominal = controller.nominal;
    tuned.heading = controller.heading;
    tuned.sweep = controller.sweep;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ofn_tracking_sweep: %s\n", e.what());
    return 2;
  }
  const double kt = 1852.0 / 3600.0;
  const double w20 = turbulence == "light"      ? 15 * kt
                     : turbulence == "moderate" ? 30 * kt
                     : turbulence == "severe"   ? 45 * kt
                                                : 0.0;
  const std::vector<double> mass_scales = {0.8, 1.0, 1.2, 1.3};
  const std::vector<AirframeError> airframes = {{"nominal", 1.0, 1.0},
                                                {"inertia x1.3, lags x1.5", 1.3, 1.5}};
  const std::vector<double> winds_kt = {0, 10, 20};

  std::filesystem::create_directories(out_dir);
  std::ofstream md(out_dir + "/tracking_sweep.md");
  std::ofstream csv(out_dir + "/tracking_sweep.csv");
  csv << "mass_scale,airframe,wind [kt],turbulence,adaptive_rms [m],adaptive_max [m],"
         "baseline_rms [m],baseline_max [m]\n";
  md << "Controller config `" << config_path << "`.\n\n"
     << "Tracking error (m, commanded minus true position) on `" << base.name << "`, " << duration
     << " s per case flown back and forth, crosswind with " << turbulence
     << " Dryden turbulence (seeded), yaw sweep on.\n\n"
     << "| mass | inertia / time constants | wind | adaptive RMS | adaptive max | "
        "non-adaptive RMS | non-adaptive max | RMS change |\n"
     << "|---|---|---|---|---|---|---|---|\n";
  ofn::sim::TrackingFlightConfig config;
  config.duration = duration;
  for (const auto& airframe : airframes)
    for (double mass : mass_scales)
      for (double wind : winds_kt) {
        ofn::Scenario s = base;
        s.vehicle.mass_scale = mass;
        s.vehicle.inertia_scale = ofn::Vec3::Constant(airframe.inertia_scale);
        s.vehicle.actuator_time_scale = airframe.time_scale;
        s.wind = ofn::Vec3(0, wind * kt, 0);  // across the northbound course
        s.disturbances.turbulence.wind_at_20ft = w20;
        ofn::sim::TrackingSetup adaptive = tuned, baseline = tuned;
        baseline.adaptive.enabled = false;
        const auto a = ofn::sim::fly_tracking(s, adaptive, config);
        const auto b = ofn::sim::fly_tracking(s, baseline, config);
        auto fmt = [](double v) {
          char buf[32];
          std::snprintf(buf, sizeof buf, v < 100 ? "%.2f" : "%.0f", v);
          return std::string(buf);
        };
        const double change = 100.0 * (a.rms_error - b.rms_error) / b.rms_error;
        md << "| " << mass << " | " << airframe.name << " | " << wind << " kt | "
           << fmt(a.rms_error) << " | " << fmt(a.max_error) << " | " << fmt(b.rms_error) << " | "
           << fmt(b.max_error) << " | " << (change > 0 ? "+" : "") << static_cast<int>(change)
           << " % |\n";
        csv << mass << ",\"" << airframe.name << "\"," << wind << "," << turbulence << ","
            << a.rms_error << "," << a.max_error << "," << b.rms_error << "," << b.max_error
            << "\n";
        std::printf(
            "mass %.1f  %-24s wind %2.0f kt  adaptive %7.2f / %7.2f m  "
            "non-adaptive %8.2f / %8.2f m\n",
            mass, airframe.name, wind, a.rms_error, a.max_error, b.rms_error, b.max_error);
        std::fflush(stdout);
      }
  std::printf("wrote %s/tracking_sweep.md and tracking_sweep.csv\n", out_dir.c_str());
  return 0;
}
