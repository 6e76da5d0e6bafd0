// sensor_interface: time-aligns the raw LIDAR returns with navigation,
// rejects saturated / max-range / invalid returns and spikes, and publishes
// the scan in the world frame (SCAN_WORLD).

#include <CLI/CLI.hpp>

#include "ofn/common/service_main.hpp"
#include "ofn/sensor_interface/sensor_interface_service.hpp"

int main(int argc, char** argv) {
  ofn::CommandLine app{"ofn_sensor_interface",
                       "ofn sensor_interface: LIDAR scans to world-frame points"};
  ofn::CommonOptions options;
  ofn::add_common_options(app, options);
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;

  return ofn::guarded_main("ofn_sensor_interface", [&] {
    auto reader = options.config.empty() ? ofn::YamlReader::empty("(defaults)")
                                         : ofn::YamlReader::load_file(options.config);
    auto config = ofn::sensing::load_sensor_interface_config(reader);
    auto lcm = ofn::open_lcm(options);
    auto clock = ofn::make_clock(options.clock);
    ofn::sensing::SensorInterfaceService service(*lcm, *clock, config);
    service.node().log().info("clock {}", clock->describe());
    return ofn::run_nodes(*lcm, *clock, {&service.node()});
  });
}
