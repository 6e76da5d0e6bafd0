// ofn_heartbeat_probe: the ears of the launcher's hang watchdog
// (deploy/launch.py). Prints one line for every heartbeat heard on the bus
// (HeartbeatProbe: "heartbeat <channel> <pid> <utime>") and "tick" once a
// second of monotonic time, so the launcher knows the probe itself runs. It
// only listens: it publishes nothing, not even a heartbeat of its own.
// Refused messages are counted and the last reason printed once a second.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>

#include "ofn/bus_auth/authenticator.hpp"
#include "ofn/common/clock.hpp"
#include "ofn/common/command_line.hpp"
#include "ofn/common/service_main.hpp"
#include "ofn/tools/heartbeat_probe.hpp"

namespace {

struct Listener {
  ofn::report::HeartbeatProbe probe;
  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    const std::string line = probe.line(channel, rbuf->data, rbuf->data_size);
    if (!line.empty()) std::printf("%s\n", line.c_str());
  }
};

}  // namespace

int main(int argc, char** argv) {
  ofn::CommandLine app{"ofn_heartbeat_probe",
                       "ofn heartbeat probe: prints every heartbeat on the bus, for the launcher"};
  std::string lcm_url, bus_keys;
  app.add_option("--lcm-url", lcm_url,
                 "LCM URL (default: $LCM_DEFAULT_URL or " + std::string(ofn::kDefaultLcmUrl) + ")");
  app.add_option("--bus-keys", bus_keys,
                 "authenticated bus: keyring directory made by ofn_bus_keygen; only signed "
                 "heartbeats are heard (default: an open bus)")
      ->check(CLI::ExistingDirectory);
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;

  return ofn::guarded_main("ofn_heartbeat_probe", [&] {
    std::optional<ofn::bus_auth::Verifier> verifier;
    if (!bus_keys.empty()) {
      auto wall = std::make_shared<ofn::WallClock>();
      verifier.emplace(ofn::bus_auth::load_verifier(bus_keys, [wall] { return wall->now(); }));
    }
    ofn::CommonOptions options;
    options.lcm_url = lcm_url;
    options.log_level = "warn";
    auto lcm = ofn::open_lcm(options);
    Listener listener{ofn::report::HeartbeatProbe(std::move(verifier))};
    lcm->subscribe("HEARTBEAT_.*", &Listener::on_message, &listener);

    using std::chrono::steady_clock;
    auto next_tick = steady_clock::now();
    int64_t reported_refusals = 0;
    while (true) {
      const auto now = steady_clock::now();
      if (now >= next_tick) {
        std::printf("tick\n");
        if (listener.probe.refused() != reported_refusals) {
          reported_refusals = listener.probe.refused();
          std::printf("refused %lld heartbeat message(s) so far; the last: %s\n",
                      static_cast<long long>(reported_refusals),
                      listener.probe.last_reason().c_str());
        }
        std::fflush(stdout);
        next_tick = now + std::chrono::seconds(1);
      }
      const auto wait =
          std::chrono::duration_cast<std::chrono::milliseconds>(next_tick - steady_clock::now());
      const int status =
          lcm->handleTimeout(static_cast<int>(std::max<int64_t>(0, wait.count())) + 1);
      if (status < 0) {
        std::cerr << "ofn_heartbeat_probe: LCM receive failed; stopping\n";
        return ofn::kExitRuntimeError;
      }
      std::fflush(stdout);
    }
  });
}
