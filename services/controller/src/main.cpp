// controller: waypoint guidance, avoidance-trajectory following and the
// outer/inner model-inversion loops; ACTUATOR_CMD out at the control rate.

#include <CLI/CLI.hpp>

#include "ofn/common/service_main.hpp"
#include "ofn/controller/controller_service.hpp"

int main(int argc, char** argv) {
  ofn::CommandLine app{"ofn_controller",
                       "ofn controller: trajectory follower and waypoint guidance"};
  ofn::CommonOptions options;
  ofn::add_common_options(app, options);
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;

  return ofn::guarded_main("ofn_controller", [&] {
    auto reader = options.config.empty() ? ofn::YamlReader::empty("(defaults)")
                                         : ofn::YamlReader::load_file(options.config);
    auto config = ofn::control::load_controller_config(reader);
    auto lcm = ofn::open_lcm(options);
    auto clock = ofn::make_clock(options.clock);
    ofn::control::ControllerService service(*lcm, *clock, config);
    service.node().log().info("clock {}", clock->describe());
    return ofn::run_nodes(*lcm, *clock, {&service.node()});
  });
}
