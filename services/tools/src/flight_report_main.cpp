// ofn_flight_report: LCM log -> CSV per channel + summary (+ plots via
// plot_flight.py, which the Makefile and the runner call).

#include <iostream>

#include <CLI/CLI.hpp>

#include "ofn/common/config.hpp"
#include "ofn/common/service_main.hpp"
#include "ofn/tools/flight_report.hpp"

int main(int argc, char** argv) {
  CLI::App app{"ofn flight report: turns an LCM flight log into CSV files and a summary"};
  std::string log_path, out_dir, scenario_path;
  app.add_option("--log", log_path, "LCM log file (lcm-logger output)")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--out", out_dir, "folder for the CSV and summary files")->required();
  app.add_option("--scenario", scenario_path, "scenario file: timing gates and display unit")
      ->check(CLI::ExistingFile);
  app.failure_message(CLI::FailureMessage::help);
  CLI11_PARSE(app, argc, argv);
  return ofn::guarded_main("ofn_flight_report", [&] {
    std::optional<ofn::Scenario> scenario;
    if (!scenario_path.empty()) scenario = ofn::load_scenario(scenario_path);
    const auto result = ofn::report::write_flight_report(log_path, out_dir, scenario);
    std::cout << result.text;
    return 0;
  });
}
