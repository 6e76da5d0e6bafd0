#include "ofn/common/service_main.hpp"

#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <iostream>

#include "ofn/common/channels.hpp"
#include "ofn/common/config.hpp"
#include "ofn/common/logging.hpp"
#include "ofn/common/sim_clock_guard.hpp"
#include "ofn/common/validate/sim_clock.hpp"

namespace ofn {
namespace {

std::atomic<bool> g_stop{false};
void on_signal(int) {
  g_stop.store(true);
}

}  // namespace

void add_common_options(CommandLine& app, CommonOptions& options, bool with_clock,
                        bool with_config) {
  if (with_config)
    app.add_option("--config", options.config,
                   "service configuration file (YAML) (default: none, the built-in defaults)")
        ->check(CLI::ExistingFile);
  app.add_option("--lcm-url", options.lcm_url,
                 "LCM URL (default: $LCM_DEFAULT_URL or " + std::string(kDefaultLcmUrl) + ")");
  if (with_clock)
    app.add_option("--clock", options.clock,
                   "time source: wall (field) or sim (follow SIM_CLOCK from vehicle_sim)")
        ->check(CLI::IsMember({"wall", "sim"}));
  app.add_option("--bus-keys", options.bus_keys,
                 "authenticated bus: keyring directory made by ofn_bus_keygen (default: an "
                 "open bus)")
      ->check(CLI::ExistingDirectory);
  app.add_option("--bus-role", options.bus_role,
                 "authenticated bus: this host's role in the keyring (gcs, onboard1, onboard2); "
                 "needed with --bus-keys (default: none)");
  app.add_option("--log-level", options.log_level, "trace, debug, info, warn, error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
}

void LcmCloser::operator()(lcm::LCM* lcm) const {
  if (!lcm) return;
  detach_authenticator(*lcm);
  delete lcm;
}

LcmHandle open_lcm(const CommonOptions& options) {
  set_log_level(options.log_level);
  if (options.bus_keys.empty() != options.bus_role.empty())
    throw std::invalid_argument(
        "--bus-keys and --bus-role go together: the keyring and this host's role in it");
  std::shared_ptr<bus_auth::Authenticator> authenticator;
  if (!options.bus_keys.empty()) {
    // Sequence numbers are wall time whatever the service's clock: they
    // order messages between hosts, not simulation events.
    auto wall = std::make_shared<WallClock>();
    authenticator = std::make_shared<bus_auth::Authenticator>(bus_auth::load_authenticator(
        options.bus_keys, options.bus_role, [wall] { return wall->now(); }));
  }
  std::string url = options.lcm_url;
  if (url.empty()) {
    const char* env = std::getenv("LCM_DEFAULT_URL");
    url = env && *env ? env : kDefaultLcmUrl;
  }
  LcmHandle lcm(new lcm::LCM(url));
  if (!lcm->good())
    throw std::runtime_error("cannot open LCM at '" + url +
                             "' (is multicast routed? try: ip route add 224.0.0.0/4 dev lo)");
  if (authenticator) attach_authenticator(*lcm, std::move(authenticator));
  return lcm;
}

std::unique_ptr<Clock> make_clock(const std::string& kind) {
  if (kind == "wall") return std::make_unique<WallClock>();
  if (kind == "sim") return std::make_unique<SimFollowClock>();
  throw std::invalid_argument("unknown clock '" + kind + "' (expected wall or sim)");
}

int run_nodes(lcm::LCM& lcm, Clock& clock, const std::vector<Node*>& nodes,
              const std::function<bool()>& keep_running) {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  // A following clock advances on SIM_CLOCK; timers then fire on the
  // message, so each service steps in simulation time.
  // The first node owns the subscription, so its heartbeat counts bad
  // SIM_CLOCK messages like any other input.
  // A stamp that jumps is refused (SimClockGuard), unless it only makes up
  // for a silence of this process; a restarted simulation is followed once
  // it has kept to its new time, and every timer starts afresh.
  auto* follower = dynamic_cast<SimFollowClock*>(&clock);
  auto guard = std::make_shared<SimClockGuard>();
  if (follower && !nodes.empty()) {
    nodes.front()->subscribe<sim_clock_t>(
        channels::kSimClock,
        [follower, guard, nodes](const sim_clock_t& m) {
          const Utime arrival = std::chrono::duration_cast<std::chrono::microseconds>(
                                    std::chrono::steady_clock::now().time_since_epoch())
                                    .count();
          switch (guard->offer(m.utime, arrival)) {
            case SimClockGuard::Verdict::kAccepted:
              follower->update(m.utime);
              break;
            case SimClockGuard::Verdict::kRejected:
              nodes.front()->reject(channels::kSimClock, guard->reason());
              break;
            case SimClockGuard::Verdict::kCaughtUp:
              // This process heard nothing for a while (stopped, starved,
              // cut off): each timer fires once for the time it missed.
              nodes.front()->log().warn("SIM_CLOCK {}: following it", guard->reason());
              follower->update(m.utime);
              break;
            case SimClockGuard::Verdict::kResynced:
              nodes.front()->log().warn("SIM_CLOCK moved to a new timeline ({}): following it",
                                        guard->reason());
              follower->update(m.utime);
              for (Node* node : nodes) node->restart_timers();
              break;
          }
        },
        SubscribeOptions{0.0, 0.0});
  }

  while (!g_stop.load() && (!keep_running || keep_running())) {
    Utime next = INT64_MAX;
    for (Node* node : nodes) {
      node->fire_due_timers();
      next = std::min(next, node->next_deadline());
    }
    int wait_ms = 50;
    const double scale = clock.wall_seconds_per_clock_second();
    if (scale > 0 && next != INT64_MAX) {
      // Deadlines are in timer time (monotonic for the wall clock).
      const double wait = to_seconds(next - clock.timer_now()) * scale;
      wait_ms = static_cast<int>(std::clamp(wait * 1000.0, 0.0, 50.0));
    }
    if (lcm.handleTimeout(wait_ms) < 0) {
      // A stop signal interrupts the wait; that is a clean stop.
      if (g_stop.load()) break;
      if (errno == EINTR) continue;
      std::cerr << "LCM receive failed; stopping\n";
      return 1;
    }
    // Drain what else arrived before running timers again, but bounded so
    // that a flood of messages cannot starve the timers.
    for (int i = 0; i < 1000 && lcm.handleTimeout(0) > 0; ++i) {
    }
  }
  return 0;
}

int guarded_main(const std::string& program, const std::function<int()>& body) {
  try {
    return body();
  } catch (const ConfigError& e) {
    std::cerr << program << ": configuration error: " << e.what() << "\n";
    return kExitInputError;
  } catch (const std::invalid_argument& e) {
    std::cerr << program << ": " << e.what() << "\n";
    return kExitInputError;
  } catch (const std::exception& e) {
    std::cerr << program << ": " << e.what() << "\n";
    return kExitRuntimeError;
  }
}

}  // namespace ofn
