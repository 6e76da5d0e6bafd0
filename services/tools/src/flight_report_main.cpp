// ofn_flight_report: LCM log -> CSV per channel + summary (+ plots via
// plot_flight.py, which the Makefile and the runner call). The exit code
// carries the verdict, so scripts can stop on a failed flight.

#include <iostream>

#include <CLI/CLI.hpp>

#include "ofn/common/config.hpp"
#include "ofn/common/service_main.hpp"
#include "ofn/controller/controller_config.hpp"
#include "ofn/tools/flight_report.hpp"

int main(int argc, char** argv) {
  ofn::CommandLine app{"ofn_flight_report",
                       "ofn flight report: turns an LCM flight log into CSV files and a summary"};
  std::string log_path, out_dir, scenario_path, controller_config_path, bus_keys;
  app.add_option("--log", log_path, "LCM log file (lcm-logger output)")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--out", out_dir, "folder for the CSV and summary files")->required();
  app.add_option("--scenario", scenario_path,
                 "scenario file: timing gates, obstacles and ground, display unit")
      ->check(CLI::ExistingFile);
  app.add_option("--controller-config", controller_config_path,
                 "the controller's config the flight was flown with, for the bound of its "
                 "pseudo-control (default: the controller's defaults)")
      ->check(CLI::ExistingFile);
  app.add_option("--bus-keys", bus_keys,
                 "keyring of the authenticated bus the log was recorded on (its policy.yaml "
                 "and public keys): read only what its roles signed on their channels (default: "
                 "none, every message read)")
      ->check(CLI::ExistingDirectory);
  app.footer(
      "Exit code: 0 when the flight's outcome is success or safe_stop, 1 when it is "
      "failure, 2 for bad arguments or an unreadable log.");
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;
  return ofn::guarded_main("ofn_flight_report", [&] {
    std::optional<ofn::Scenario> scenario;
    if (!scenario_path.empty()) scenario = ofn::load_scenario(scenario_path);
    auto controller_reader = controller_config_path.empty()
                                 ? ofn::YamlReader::empty("(defaults)")
                                 : ofn::YamlReader::load_file(controller_config_path);
    const auto controller = ofn::control::load_controller_config(controller_reader);
    const ofn::report::PseudoControlBound bound{controller.gains.max_horizontal_accel,
                                                controller.gains.max_vertical_accel};
    const ofn::report::ControlStops stops{controller.nominal.min_controls.as_array(),
                                          controller.nominal.max_controls.as_array()};
    const auto result =
        ofn::report::write_flight_report(log_path, out_dir, scenario, bound, bus_keys, stops);
    std::cout << result.text;
    return result.verdict.outcome == ofn::report::Outcome::kFailure ? 1 : 0;
  });
}
