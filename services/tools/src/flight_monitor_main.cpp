// ofn_flight_monitor: watches a live flight on the bus, prints progress and
// exits when the controller reports arrival at the last waypoint (0) or when
// the wall-clock timeout passes (1). The launcher uses it to end a run.

#include <chrono>
#include <cmath>
#include <iostream>
#include <optional>

#include <CLI/CLI.hpp>

#include "ofn/common/channels.hpp"
#include "ofn/common/service_main.hpp"
#include "ofn/control_status_t.hpp"
#include "ofn/nav_state_t.hpp"

int main(int argc, char** argv) {
  CLI::App app{"ofn flight monitor: progress of a live flight; exits when it is done"};
  ofn::CommonOptions options;
  double timeout = 300.0, report_period = 5.0, linger = 1.0;
  ofn::add_common_options(app, options, /*with_clock=*/true, /*with_config=*/false);
  app.add_option("--timeout", timeout, "give up after this many wall seconds")
      ->check(CLI::PositiveNumber);
  app.add_option("--every", report_period, "seconds of flight time between progress lines")
      ->check(CLI::PositiveNumber);
  app.add_option("--linger", linger, "seconds of flight time to keep watching after arrival")
      ->check(CLI::NonNegativeNumber);
  CLI11_PARSE(app, argc, argv);

  return ofn::guarded_main("ofn_flight_monitor", [&] {
    auto lcm = ofn::open_lcm(options);
    auto clock = ofn::make_clock(options.clock);
    ofn::Node node("flight_monitor", *lcm, *clock);
    std::optional<ofn::nav_state_t> nav;
    int8_t mode = -1;
    ofn::Utime done_at = INT64_MIN;
    node.subscribe<ofn::nav_state_t>(ofn::channels::kNavState,
                                     [&](const ofn::nav_state_t& m) { nav = m; });
    node.subscribe<ofn::control_status_t>(
        ofn::channels::kControlStatus, [&](const ofn::control_status_t& m) {
          if (m.mode == ofn::control_status_t::DONE && done_at == INT64_MIN) {
            done_at = m.utime;
            std::cout << "monitor: arrived at the last waypoint at t=" << ofn::to_seconds(m.utime)
                      << " s" << std::endl;
          }
          mode = m.mode;
        });
    node.add_timer(
        report_period,
        [&] {
          if (!nav) {
            std::cout << "monitor: waiting for NAV_STATE" << std::endl;
            return;
          }
          const double speed = std::hypot(nav->velocity[0], nav->velocity[1], nav->velocity[2]);
          std::printf(
              "monitor: t=%6.1f s  north %8.1f m  east %6.1f m  alt %6.1f m  speed %5.2f m/s  mode "
              "%d\n",
              ofn::to_seconds(nav->utime), nav->position[0], nav->position[1], -nav->position[2],
              speed, static_cast<int>(mode));
          std::fflush(stdout);
        },
        "progress");
    const auto wall_start = std::chrono::steady_clock::now();
    bool timed_out = false;
    ofn::run_nodes(*lcm, *clock, {&node}, [&] {
      if (done_at != INT64_MIN && clock->now() - done_at >= ofn::to_utime(linger)) return false;
      timed_out =
          std::chrono::steady_clock::now() - wall_start > std::chrono::duration<double>(timeout);
      return !timed_out;
    });
    if (timed_out) {
      std::cerr << "monitor: no arrival within " << timeout << " s" << std::endl;
      return 1;
    }
    return done_at != INT64_MIN ? 0 : 1;
  });
}
