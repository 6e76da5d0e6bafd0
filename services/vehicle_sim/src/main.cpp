// vehicle_sim: the airframe, nav system and (later) LIDAR head stand-in.
// It is the simulation's time master: its clock runs at --rtf times the
// wall clock and it publishes SIM_CLOCK for everyone else.

#include <CLI/CLI.hpp>

#include "ofn/common/config.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/common/service_main.hpp"
#include "ofn/vehicle_sim/vehicle_sim_service.hpp"

int main(int argc, char** argv) {
  ofn::CommandLine app{"ofn_vehicle_sim",
                       "ofn vehicle_sim: 6-DOF RMAX-class rotorcraft simulation"};
  ofn::CommonOptions options;
  std::string scenario_path;
  double real_time_factor = 1.0;
  std::string checkpoint_path;
  ofn::add_common_options(app, options, /*with_clock=*/false);
  app.add_option("--scenario", scenario_path, "scenario file (YAML)")->required();
  // --rtf as in deploy/launch.py, fly.sh and `make run RTF=`; the long
  // name is kept for the command lines written with it.
  app.add_option("--rtf,--real-time-factor", real_time_factor,
                 "real-time factor: simulation speed, 1 = real time")
      ->check(ofn::number_between(0.01, 1000.0));
  app.add_option("--checkpoint", checkpoint_path,
                 "file the flight's state is saved to as it flies; when it exists at the start, "
                 "the flight resumes from it (a restart after a crash) (default: none, no "
                 "checkpoint)");
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;

  return ofn::guarded_main("ofn_vehicle_sim", [&] {
    const ofn::Scenario scenario = ofn::load_scenario(scenario_path);
    auto reader = options.config.empty() ? ofn::YamlReader::empty("(defaults)")
                                         : ofn::YamlReader::load_file(options.config);
    auto config = ofn::vehicle::load_vehicle_sim_config(reader);
    const auto resume = checkpoint_path.empty()
                            ? std::nullopt
                            : ofn::vehicle::read_checkpoint_file(checkpoint_path);
    auto lcm = ofn::open_lcm(options);
    ofn::ScaledWallClock clock(resume ? resume->time_us : 0, real_time_factor);
    ofn::vehicle::VehicleSimService service(*lcm, clock, scenario, config, real_time_factor,
                                            resume);
    if (!checkpoint_path.empty())
      service.set_checkpoint_sink([&checkpoint_path](const ofn::vehicle::VehicleCheckpoint& c) {
        ofn::vehicle::write_checkpoint_file(checkpoint_path, c);
      });
    service.node().log().info("scenario '{}', clock {}", scenario.name, clock.describe());
    const int code = ofn::run_nodes(*lcm, clock, {&service.node()});
    // Wall time the simulated world waited for its simulator: how far the
    // run fell short of its real-time factor.
    service.node().log().info("the clock waited {:.2f} s of wall time for the simulator",
                              clock.paused());
    if (service.failsafe().enabled())
      service.node().log().info(
          "the airframe's stabiliser took over {} times (each after {:.2f} s without an actuator "
          "command)",
          service.failsafe().takeovers(), config.command_timeout);
    return code;
  });
}
