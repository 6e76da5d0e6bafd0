// ofn_replay: replays a recorded flight into fresh mapper and planner
// services and compares what they publish with the recording.

#include <cstdio>
#include <filesystem>
#include <iostream>

#include <CLI/CLI.hpp>

#include "ofn/common/logging.hpp"
#include "ofn/common/service_main.hpp"
#include "ofn/sim/replay.hpp"

int main(int argc, char** argv) {
  ofn::CommandLine app{
      "ofn_replay",
      "ofn log replay: feeds a recorded flight's inputs into fresh sensor_interface, mapper, "
      "global_planner and rh_optimizer services and compares their outputs with the recording. "
      "Exit 0: every compared channel matches; 1: they differ; 2: bad input."};
  std::string log_path, config_dir = "config", out_dir, service_list, clock = "auto";
  std::string log_level = "warn";
  double tolerance = 0.0, stamp_tolerance = 0.0;
  service_list = "sensor_interface,mapper,global_planner,rh_optimizer";
  app.add_option("--log", log_path, "recorded flight (LCM log: ofn_sim_runner or lcm-logger)")
      ->required();
  auto* config_option =
      app.add_option("--config-dir", config_dir,
                     "folder with sensor_interface.yaml, mapper.yaml, global_planner.yaml, "
                     "rh_optimizer.yaml (missing files: defaults)");
  app.add_option("--out", out_dir, "folder for replayed.lcm (recorded inputs, replayed outputs)");
  app.add_option("--services", service_list, "comma-separated services to replay");
  app.add_option("--clock", clock,
                 "replay clock: log (log timestamps), sim (SIM_CLOCK messages), auto (log for "
                 "simulation-time logs, sim for wall-time logs with SIM_CLOCK)")
      ->check(CLI::IsMember({"auto", "log", "sim"}));
  app.add_option("--tolerance", tolerance,
                 "largest field difference (m, s, m/s, cost) still counted as a match; 0: "
                 "identical bytes")
      ->check(ofn::non_negative_number());
  app.add_option("--stamp-tolerance", stamp_tolerance,
                 "largest time-stamp difference (s) still counted as a match; for logs of "
                 "services that followed SIM_CLOCK in real time")
      ->check(ofn::non_negative_number());
  app.add_option("--log-level", log_level, "services' log level")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;

  return ofn::guarded_main("ofn_replay", [&]() -> int {
    ofn::set_log_level(log_level);
    try {
      ofn::sim::ReplayOptions options;
      options.services = ofn::sim::parse_service_list(service_list);
      // As ofn_sim_runner: without ./config and no --config-dir, service defaults.
      if (config_option->count() == 0 && !std::filesystem::is_directory(config_dir)) {
        std::cerr << "ofn_replay: no ./config folder: service defaults\n";
        config_dir.clear();
      }
      options.configs = ofn::sim::load_replay_configs(config_dir);
      options.clock = clock == "log"   ? ofn::sim::ReplayClockSource::kLogTime
                      : clock == "sim" ? ofn::sim::ReplayClockSource::kSimClock
                                       : ofn::sim::ReplayClockSource::kAuto;
      options.tolerance = tolerance;
      options.stamp_tolerance = stamp_tolerance;
      if (!out_dir.empty()) {
        std::filesystem::create_directories(out_dir);
        options.replayed_log_path = (std::filesystem::path(out_dir) / "replayed.lcm").string();
      }
      const ofn::sim::ReplayResult result = ofn::sim::replay_log(log_path, options);
      std::cout << ofn::sim::format_comparison(result);
      if (!out_dir.empty()) std::cout << "replayed log: " << options.replayed_log_path << "\n";
      return result.matches() ? 0 : 1;
    } catch (const ofn::sim::ReplayInputError& e) {
      std::cerr << "ofn_replay: error: " << e.what() << "\n";
      return 2;
    }
  });
}
