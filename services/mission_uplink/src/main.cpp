// mission_uplink: the ground station's waypoint plan uplink.

#include <CLI/CLI.hpp>

#include "ofn/common/service_main.hpp"
#include "ofn/mission_uplink/mission_uplink_service.hpp"

int main(int argc, char** argv) {
  ofn::CommandLine app{"ofn_mission_uplink",
                       "ofn mission_uplink: publishes a scenario's waypoint plan as MISSION"};
  ofn::CommonOptions options;
  std::string scenario_path;
  ofn::add_common_options(app, options, /*with_clock=*/true, /*with_config=*/false);
  app.add_option("--scenario", scenario_path, "scenario file (YAML)")->required();
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;

  return ofn::guarded_main("ofn_mission_uplink", [&] {
    auto lcm = ofn::open_lcm(options);
    auto clock = ofn::make_clock(options.clock);
    ofn::uplink::MissionUplinkService service(*lcm, *clock, scenario_path);
    service.node().log().info("scenario {}: {} waypoints, clock {}", scenario_path,
                              service.mission().num_waypoints, clock->describe());
    return ofn::run_nodes(*lcm, *clock, {&service.node()});
  });
}
