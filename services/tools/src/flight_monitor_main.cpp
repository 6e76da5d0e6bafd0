// ofn_flight_monitor: watches a live flight on the bus, prints progress and
// exits when the vehicle has arrived at the last waypoint (0: the controller
// says DONE for --linger seconds while navigation puts the vehicle there,
// see ArrivalWatch) or when the wall-clock timeout passes (1). The launcher
// uses it to end a run. It also says which services have fallen silent (no
// heartbeat for --silence wall seconds, see HeartbeatWatch) and when they
// are heard again, and, with each progress line, which services' inputs
// lost or duplicated messages since the last (their heartbeats' counts of
// the publishers' sequence numbers, see InputLossTally).

#include <chrono>
#include <cmath>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "ofn/common/channels.hpp"
#include "ofn/common/message_names.hpp"
#include "ofn/common/mission_plan.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/common/service_main.hpp"
#include "ofn/common/validate/control_status.hpp"
#include "ofn/common/validate/heartbeat.hpp"
#include "ofn/common/validate/mission.hpp"
#include "ofn/common/validate/nav_state.hpp"
#include "ofn/control_status_t.hpp"
#include "ofn/heartbeat_t.hpp"
#include "ofn/mission_t.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/tools/arrival_watch.hpp"
#include "ofn/tools/heartbeat_watch.hpp"
#include "ofn/tools/input_loss.hpp"
#include "ofn/tools/monitor_line.hpp"

int main(int argc, char** argv) {
  ofn::CommandLine app{"ofn_flight_monitor",
                       "ofn flight monitor: progress of a live flight; exits when it is done"};
  ofn::CommonOptions options;
  double timeout = 300.0, report_period = 5.0, linger = 1.0;
  std::string scenario_path;
  double silence = 3.0;
  // The flight's services (deploy/processes.yaml), the monitor excepted.
  std::vector<std::string> watched = {"vehicle_sim",       "controller",       "mission_uplink",
                                      "obstacle_injector", "sensor_interface", "mapper",
                                      "global_planner",    "rh_optimizer"};
  ofn::add_common_options(app, options, /*with_clock=*/true, /*with_config=*/false);
  app.add_option("--timeout", timeout, "give up after this many wall seconds (0: never)")
      ->check(ofn::non_negative_number());
  app.add_option("--every", report_period, "seconds of flight time between progress lines")
      ->check(ofn::positive_number());
  app.add_option("--linger", linger,
                 "seconds of flight time over which every status must say DONE, with the "
                 "vehicle at the last waypoint, before the flight counts as arrived")
      ->check(ofn::non_negative_number());
  app.add_option("--scenario", scenario_path,
                 "scenario file: progress in its unit (feet for the courses); without it, metres");
  app.add_option("--silence", silence,
                 "wall seconds without a heartbeat after which a service is reported silent "
                 "(0: no report)")
      ->check(ofn::non_negative_number());
  app.add_option("--services", watched, "services whose heartbeats are watched")->delimiter(',');
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;

  return ofn::guarded_main("ofn_flight_monitor", [&] {
    ofn::report::DisplayUnit unit;
    if (!scenario_path.empty()) {
      const ofn::Scenario scenario = ofn::load_scenario(scenario_path);
      unit = {scenario.display_unit, scenario.metres_per_unit};
    }
    auto lcm = ofn::open_lcm(options);
    auto clock = ofn::make_clock(options.clock);
    ofn::Node node("flight_monitor", *lcm, *clock);
    std::optional<ofn::nav_state_t> nav;
    int8_t mode = -1;
    ofn::report::ArrivalRules rules;
    rules.linger = linger;
    ofn::report::ArrivalWatch arrival(rules);
    int64_t doubts_reported = 0;
    node.subscribe<ofn::nav_state_t>(ofn::channels::kNavState, [&](const ofn::nav_state_t& m) {
      nav = m;
      arrival.on_navigation(m.utime, ofn::to_vec3(m.position));
    });
    node.subscribe<ofn::mission_t>(
        ofn::channels::kMission,
        [&](const ofn::mission_t& m) {
          if (m.waypoints.empty()) return;
          const auto& last = m.waypoints.back();
          arrival.set_goal(m.mission_id, ofn::to_vec3(last.position), last.capture_radius);
        },
        ofn::SubscribeOptions{0.0, 0.0});
    node.subscribe<ofn::control_status_t>(
        ofn::channels::kControlStatus, [&](const ofn::control_status_t& m) {
          const bool had_arrived = arrival.arrived_at().has_value();
          arrival.on_status(m.utime, m.mode == ofn::control_status_t::DONE, m.mission_id);
          if (!had_arrived && arrival.arrived_at())
            std::cout << "monitor: arrived at the last waypoint at t="
                      << ofn::to_seconds(*arrival.arrived_at()) << " s" << std::endl;
          // A DONE that does not fit the vehicle's state is reported, once
          // per kind of doubt run, not obeyed.
          if (arrival.unconfirmed_done() > doubts_reported) {
            if (doubts_reported == 0 || arrival.unconfirmed_done() % 100 == 1)
              std::cout << "monitor: DONE not taken (" << arrival.last_doubt() << "; "
                        << arrival.unconfirmed_done() << " so far)" << std::endl;
            doubts_reported = arrival.unconfirmed_done();
          }
          mode = m.mode;
        });
    ofn::report::InputLossTally loss;
    node.add_timer(
        report_period,
        [&] {
          if (!nav) {
            std::cout << "monitor: waiting for NAV_STATE" << std::endl;
          } else {
            std::cout << "monitor: "
                      << ofn::report::progress_line(
                             ofn::to_seconds(nav->utime), ofn::to_vec3(nav->position),
                             ofn::to_vec3(nav->velocity),
                             mode < 0 ? "-" : ofn::control_mode_name(mode), unit)
                      << std::endl;
          }
          // Loss is shown when there is some: per service, each input that
          // lost or duplicated more since the last line, with its totals.
          for (const auto& line : ofn::report::growth_lines(loss.grown()))
            std::cout << "monitor: messages lost: " << line << std::endl;
        },
        "progress");
    const auto wall_start = std::chrono::steady_clock::now();
    auto wall_seconds = [&] {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    };
    std::optional<ofn::report::HeartbeatWatch> heartbeats;
    if (silence > 0) heartbeats.emplace(silence);
    for (const std::string& service : watched)
      node.subscribe<ofn::heartbeat_t>(
          ofn::heartbeat_channel(service),
          [&heartbeats, &loss, &wall_seconds, &node, service](const ofn::heartbeat_t& m) {
            // A heartbeat naming another service is no sign of life of this one,
            // and its counts are not this service's.
            if (m.service != service) {
              node.reject(ofn::heartbeat_channel(service), "names another service");
              return;
            }
            if (heartbeats) heartbeats->heard(service, m.service, wall_seconds());
            loss.heard(m);
          },
          ofn::SubscribeOptions{0.0, 0.0});
    auto names = [](const std::vector<std::string>& list) {
      std::ostringstream out;
      for (size_t i = 0; i < list.size(); ++i) out << (i ? ", " : "") << list[i];
      return out.str();
    };
    bool timed_out = false;
    ofn::run_nodes(*lcm, *clock, {&node}, [&] {
      if (heartbeats) {
        const auto changes = heartbeats->check(wall_seconds());
        if (!changes.silent.empty())
          std::cout << "monitor: no heartbeat for " << silence
                    << " s (wall) from: " << names(changes.silent) << std::endl;
        if (!changes.back.empty())
          std::cout << "monitor: heartbeats again from: " << names(changes.back) << std::endl;
      }
      if (arrival.arrived_at()) return false;
      timed_out = timeout > 0 && wall_seconds() > timeout;
      return !timed_out;
    });
    if (timed_out) {
      std::cerr << "monitor: no arrival within " << timeout << " s" << std::endl;
      return 1;
    }
    return arrival.arrived_at() ? 0 : 1;
  });
}
