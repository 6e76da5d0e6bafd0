// rh_optimizer (Onboard2): receding-horizon trajectory optimisation and the
// switch from nominal waypoint guidance to avoidance.

#include <CLI/CLI.hpp>

#include "ofn/common/service_main.hpp"
#include "ofn/rh_optimizer/rh_optimizer_service.hpp"

int main(int argc, char** argv) {
  ofn::CommandLine app{
      "ofn_rh_optimizer",
      "ofn rh_optimizer: B-spline trajectory optimisation in sensor range (REF_TRAJ)"};
  ofn::CommonOptions options;
  ofn::add_common_options(app, options);
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;

  return ofn::guarded_main("ofn_rh_optimizer", [&] {
    auto reader = options.config.empty() ? ofn::YamlReader::empty("(defaults)")
                                         : ofn::YamlReader::load_file(options.config);
    auto config = ofn::rh::load_rh_optimizer_config(reader);
    auto lcm = ofn::open_lcm(options);
    auto clock = ofn::make_clock(options.clock);
    ofn::rh::RhOptimizerService service(*lcm, *clock, config);
    service.node().log().info("{:.0f} Hz, B-spline degree {} over {} intervals, clock {}",
                              config.rate, config.optimizer.degree, config.optimizer.intervals,
                              clock->describe());
    return ofn::run_nodes(*lcm, *clock, {&service.node()});
  });
}
