// obstacle_injector: the ground station's virtual obstacles, published on
// their scenario schedule as VIRTUAL_OBSTACLES.

#include <CLI/CLI.hpp>

#include "ofn/common/service_main.hpp"
#include "ofn/obstacle_injector/obstacle_injector_service.hpp"

int main(int argc, char** argv) {
  ofn::CommandLine app{
      "ofn_obstacle_injector",
      "ofn obstacle_injector: publishes a scenario's obstacles as VIRTUAL_OBSTACLES"};
  ofn::CommonOptions options;
  std::string scenario_path;
  ofn::add_common_options(app, options, /*with_clock=*/true, /*with_config=*/true);
  app.add_option("--scenario", scenario_path, "scenario file (YAML)")
      ->required()
      ->check(CLI::ExistingFile);
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;

  return ofn::guarded_main("ofn_obstacle_injector", [&] {
    auto reader = options.config.empty() ? ofn::YamlReader::empty("(defaults)")
                                         : ofn::YamlReader::load_file(options.config);
    auto config = ofn::injector::load_obstacle_injector_config(reader);
    auto lcm = ofn::open_lcm(options);
    auto clock = ofn::make_clock(options.clock);
    ofn::injector::ObstacleInjectorService service(*lcm, *clock, scenario_path, config);
    service.node().log().info(
        "scenario {}: {} obstacles, check {} Hz, re-send every {} s, clock {}", scenario_path,
        service.scenario().obstacles.size(), config.check_rate, config.publish_period,
        clock->describe());
    return ofn::run_nodes(*lcm, *clock, {&service.node()});
  });
}
