// ofn_sim_runner: flies a scenario with every service in one process under
// the deterministic lockstep clock, records the bus to an LCM log and writes
// the flight report. Used by tests, benchmarks and Monte Carlo batches.

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>

#include <CLI/CLI.hpp>

#include "ofn/common/config.hpp"
#include "ofn/common/logging.hpp"
#include "ofn/common/message_names.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/common/service_main.hpp"
#include "ofn/controller/controller_service.hpp"
#include "ofn/global_planner/global_planner_service.hpp"
#include "ofn/mapper/mapper_service.hpp"
#include "ofn/mission_uplink/mission_uplink_service.hpp"
#include "ofn/obstacle_injector/obstacle_injector_service.hpp"
#include "ofn/rh_optimizer/rh_optimizer_service.hpp"
#include "ofn/sensor_interface/sensor_interface_service.hpp"
#include "ofn/sim/link_faults.hpp"
#include "ofn/sim/lockstep.hpp"
#include "ofn/tools/flight_report.hpp"
#include "ofn/tools/monitor_line.hpp"
#include "ofn/vehicle_sim/vehicle_sim_service.hpp"

namespace {

ofn::YamlReader config_in(const std::string& dir, const std::string& file) {
  const std::filesystem::path path = std::filesystem::path(dir) / file;
  if (!dir.empty() && std::filesystem::exists(path))
    return ofn::YamlReader::load_file(path.string());
  return ofn::YamlReader::empty("(defaults)");
}

}  // namespace

int main(int argc, char** argv) {
  ofn::CommandLine app{"ofn_sim_runner",
                       "ofn lockstep runner: all services in one process, deterministic and fast"};
  std::string scenario_path, config_dir = "config", out_dir, log_path, log_level = "warn";
  std::string process_table = "deploy/processes.yaml";
  double max_time = 0, linger = 2.0, link_loss = 0.0, link_delay = 0.0, link_jitter = 0.0;
  uint64_t link_seed = 1;
  bool quiet = false, no_avoidance = false, link_all = false;
  app.add_option("--scenario", scenario_path, "scenario file (YAML)")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--config-dir", config_dir,
                 "folder with the services' config files, e.g. vehicle_sim.yaml, "
                 "mapper.yaml, global_planner.yaml, rh_optimizer.yaml (missing files: defaults)");
  app.add_option("--out", out_dir, "folder for the log, CSV files and summary (default: none)");
  app.add_option("--log", log_path, "LCM log to write (default: <out>/flight.lcm)");
  app.add_option("--max-time", max_time,
                 "simulated seconds before giving up (default: the scenario's max_time)")
      ->check(ofn::positive_number());
  app.add_option("--linger", linger, "simulated seconds to keep flying after arrival");
  app.add_option("--log-level", log_level, "service log level")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
  app.add_option("--link-loss", link_loss,
                 "probability that a datagram between two hosts is lost (hosts from "
                 "--process-table; a message is lost when any of its fragments is)")
      ->check(ofn::number_between(0.0, 0.99));
  app.add_option("--link-delay", link_delay, "s every message between two hosts is delayed")
      ->check(ofn::number_between(0.0, 10.0));
  app.add_option("--link-jitter", link_jitter,
                 "s of uniform jitter (+-) on that delay; messages then overtake one another")
      ->check(ofn::number_between(0.0, 10.0));
  app.add_flag("--link-all", link_all,
               "the link faults also between the services of one host (the controller-vehicle "
               "loop included)");
  app.add_option("--link-seed", link_seed, "seed of the link-fault draws");
  app.add_option("--process-table", process_table,
                 "process table naming each service's host, for the link faults");
  app.add_flag("--quiet", quiet, "no progress lines");
  app.add_flag("--no-avoidance", no_avoidance,
               "fly without global_planner and rh_optimizer (nominal waypoint guidance only)");
  app.footer(
      "Exit code: with --out, 0 when the flight's outcome is success or safe_stop and 1 "
      "when it is failure; without --out (no report, no verdict), 0 when the vehicle "
      "arrived and 1 when not; 2 for bad arguments, config or scenario.");
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;

  return ofn::guarded_main("ofn_sim_runner", [&]() -> int {
    ofn::set_log_level(log_level);
    const ofn::Scenario scenario = ofn::load_scenario(scenario_path);
    auto vehicle_reader = config_in(config_dir, "vehicle_sim.yaml");
    auto controller_reader = config_in(config_dir, "controller.yaml");
    const auto vehicle_config = ofn::vehicle::load_vehicle_sim_config(vehicle_reader);
    const auto controller_config = ofn::control::load_controller_config(controller_reader);
    auto injector_reader = config_in(config_dir, "obstacle_injector.yaml");
    auto sensor_reader = config_in(config_dir, "sensor_interface.yaml");
    auto mapper_reader = config_in(config_dir, "mapper.yaml");
    const auto injector_config = ofn::injector::load_obstacle_injector_config(injector_reader);
    const auto sensor_config = ofn::sensing::load_sensor_interface_config(sensor_reader);
    const auto mapper_config = ofn::mapping::load_mapper_config(mapper_reader);
    auto planner_reader = config_in(config_dir, "global_planner.yaml");
    auto optimizer_reader = config_in(config_dir, "rh_optimizer.yaml");
    const auto planner_config = ofn::planning::load_global_planner_config(planner_reader);
    auto optimizer_config = ofn::rh::load_rh_optimizer_config(optimizer_reader);
    // Virtual time does not advance while a solve runs, and a wall-time cap
    // would make a run depend on the machine's load: in lockstep every solve
    // is bounded by its evaluation count alone, so runs repeat to the bit.
    optimizer_config.optimizer.max_solve_time = 10.0;
    if (!out_dir.empty()) std::filesystem::create_directories(out_dir);
    if (log_path.empty() && !out_dir.empty()) log_path = out_dir + "/flight.lcm";

    ofn::sim::Lockstep lockstep;
    if (!log_path.empty()) lockstep.record(log_path);
    std::shared_ptr<ofn::sim::LinkFaults> link;
    if (link_loss > 0 || link_delay > 0 || link_jitter > 0) {
      link = std::make_shared<ofn::sim::LinkFaults>(
          ofn::sim::LinkFaultsConfig{link_loss, link_delay, link_jitter, link_all, link_seed,
                                     ofn::sim::load_service_hosts(process_table)});
      link->watch(lockstep.lcm());
      ofn::attach_link_model(lockstep.lcm(), link);
    }
    // The services' nodes leave before the handle; the link model with them.
    struct LinkDetach {
      lcm::LCM& lcm;
      ~LinkDetach() { ofn::detach_link_model(lcm); }
    } link_detach{lockstep.lcm()};
    ofn::vehicle::VehicleSimService vehicle(lockstep.lcm(), lockstep.clock(), scenario,
                                            vehicle_config);
    ofn::uplink::MissionUplinkService uplink(lockstep.lcm(), lockstep.clock(), scenario_path);
    ofn::control::ControllerService controller(lockstep.lcm(), lockstep.clock(), controller_config);
    ofn::injector::ObstacleInjectorService injector(lockstep.lcm(), lockstep.clock(), scenario_path,
                                                    injector_config);
    ofn::sensing::SensorInterfaceService sensor(lockstep.lcm(), lockstep.clock(), sensor_config);
    ofn::mapping::MapperService mapper(lockstep.lcm(), lockstep.clock(), mapper_config);
    for (ofn::Node* node : {&vehicle.node(), &uplink.node(), &controller.node(), &injector.node(),
                            &sensor.node(), &mapper.node()})
      lockstep.add(*node);
    std::optional<ofn::planning::GlobalPlannerService> planner;
    std::optional<ofn::rh::RhOptimizerService> optimizer;
    if (!no_avoidance) {
      planner.emplace(lockstep.lcm(), lockstep.clock(), planner_config);
      optimizer.emplace(lockstep.lcm(), lockstep.clock(), optimizer_config);
      lockstep.add(planner->node());
      lockstep.add(optimizer->node());
    }
    // Every service must have a host before the first message crosses.
    for (const ofn::Node* node : link ? lockstep.nodes() : std::vector<ofn::Node*>{}) {
      try {
        link->host(node->name());
      } catch (const std::out_of_range& e) {
        throw ofn::ConfigError(process_table + ": " + e.what());
      }
    }

    const double limit = max_time > 0 ? max_time : scenario.max_time;
    ofn::Utime done_at = INT64_MIN;
    double next_progress = 10.0;
    const auto wall_start = std::chrono::steady_clock::now();
    const bool arrived = lockstep.run(ofn::to_utime(limit), [&] {
      const ofn::Utime now = lockstep.clock().now();
      if (!quiet && ofn::to_seconds(now) >= next_progress) {
        const auto& s = vehicle.model().state();
        // The flight monitor's line, in the course's unit as the summary
        // that follows.
        std::cout << ofn::report::progress_line(ofn::to_seconds(now), s.position, s.velocity,
                                                ofn::control_mode_name(controller.mode()),
                                                {scenario.display_unit, scenario.metres_per_unit})
                  << std::endl;
        next_progress += 10.0;
      }
      if (controller.mode() == ofn::control_status_t::DONE && done_at == INT64_MIN) done_at = now;
      return done_at != INT64_MIN && now - done_at >= ofn::to_utime(linger);
    });
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    const double simulated = ofn::to_seconds(lockstep.clock().now());
    std::printf("lockstep: %.1f s simulated in %.2f s wall (%.0fx real time), %lld messages\n",
                simulated, wall, simulated / std::max(wall, 1e-9),
                static_cast<long long>(lockstep.messages()));
    if (!arrived) std::printf("lockstep: the vehicle did not arrive within %.0f s\n", limit);
    if (link) {
      int64_t crossing = 0, lost = 0;
      std::string by_channel;
      for (const auto& [channel, count] : link->counts()) {
        crossing += count.crossing;
        lost += count.lost;
        if (count.lost > 0)
          by_channel += " " + channel + " " + std::to_string(count.lost) + "/" +
                        std::to_string(count.crossing);
      }
      // One line, "N of M messages ... lost", that scripts read.
      std::printf(
          "link faults (%.0f %% of datagrams lost, delay %.3f +- %.3f s, %s): %lld of %lld "
          "messages lost:%s\n",
          100.0 * link_loss, link_delay, link_jitter, link_all ? "every link" : "between hosts",
          static_cast<long long>(lost), static_cast<long long>(crossing), by_channel.c_str());
    }

    if (!out_dir.empty()) {
      // Close the log before reading it back.
      lockstep.record("/dev/null");
      const ofn::report::PseudoControlBound bound{controller_config.gains.max_horizontal_accel,
                                                  controller_config.gains.max_vertical_accel};
      const auto result = ofn::report::write_flight_report(
          log_path, out_dir, scenario, bound, "",
          ofn::report::ControlStops{controller_config.nominal.min_controls.as_array(),
                                    controller_config.nominal.max_controls.as_array()});
      std::cout << result.text;
      // A safe stop does not arrive, yet is a proper end of the flight.
      return result.verdict.outcome == ofn::report::Outcome::kFailure ? 1 : 0;
    }
    // Without a report there is no verdict; arrival is all there is to go by.
    return arrived ? 0 : 1;
  });
}
