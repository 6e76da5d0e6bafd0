// global_planner (Onboard2): the coarse route over the cuboid obstacle field.

#include <CLI/CLI.hpp>

#include "ofn/common/service_main.hpp"
#include "ofn/global_planner/global_planner_service.hpp"

int main(int argc, char** argv) {
  ofn::CommandLine app{
      "ofn_global_planner",
      "ofn global_planner: dynamic programming over the cuboid node graph (GLOBAL_PATH)"};
  ofn::CommonOptions options;
  ofn::add_common_options(app, options);
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;

  return ofn::guarded_main("ofn_global_planner", [&] {
    auto reader = options.config.empty() ? ofn::YamlReader::empty("(defaults)")
                                         : ofn::YamlReader::load_file(options.config);
    auto config = ofn::planning::load_global_planner_config(reader);
    auto lcm = ofn::open_lcm(options);
    auto clock = ofn::make_clock(options.clock);
    ofn::planning::GlobalPlannerService service(*lcm, *clock, config);
    service.node().log().info("replanning at {:.1f} Hz, clock {}", config.replan_rate,
                              clock->describe());
    return ofn::run_nodes(*lcm, *clock, {&service.node()});
  });
}
