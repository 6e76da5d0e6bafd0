#pragma once
// What every service's main() shares: the common command-line options, the
// clock they select and the process loop that runs nodes on a udpm:// (or
// any) LCM URL until SIGINT/SIGTERM. The command line itself, its
// convention and the exit codes: command_line.hpp.

#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>

#include "ofn/common/clock.hpp"
#include "ofn/common/command_line.hpp"
#include "ofn/common/node.hpp"

namespace ofn {

/// Default bus: LCM's multicast group with TTL 0, so simulation traffic
/// never leaves the machine unless a deployment asks for it.
inline constexpr const char* kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0";

struct CommonOptions {
  std::string config;   // service config file (YAML); empty: defaults
  std::string lcm_url;  // empty: $LCM_DEFAULT_URL or kDefaultLcmUrl
  std::string clock = "wall";
  std::string log_level = "info";
  // Authenticated bus (docs/DEPLOYMENT.md): the keyring directory and this
  // host's role in it; both empty: an open bus.
  std::string bus_keys;
  std::string bus_role;
};

/// Adds --lcm-url, --bus-keys, --bus-role and --log-level, and --clock /
/// --config for programs that have a clock choice or a config file.
void add_common_options(CommandLine& app, CommonOptions& options, bool with_clock = true,
                        bool with_config = true);

/// Deletes an LCM handle opened by open_lcm(), and forgets its authenticator.
struct LcmCloser {
  void operator()(lcm::LCM* lcm) const;
};
using LcmHandle = std::unique_ptr<lcm::LCM, LcmCloser>;

/// Applies the log level and opens the LCM handle, authenticated when
/// --bus-keys is given (every node made on it then signs and checks);
/// throws with a clear message if the URL cannot be opened or the keyring
/// cannot be used.
LcmHandle open_lcm(const CommonOptions& options);

/// The clock named by --clock: "wall" or "sim" (follows SIM_CLOCK).
std::unique_ptr<Clock> make_clock(const std::string& kind);

/// Runs the nodes until SIGINT/SIGTERM (or until `keep_running` says no).
/// A SimFollowClock is fed from SIM_CLOCK. Returns a process exit code.
int run_nodes(lcm::LCM& lcm, Clock& clock, const std::vector<Node*>& nodes,
              const std::function<bool()>& keep_running = {});

/// Wraps a program's main so that exceptions end the process with a clear
/// message instead of a crash: kExitInputError for a ConfigError or an
/// invalid argument, kExitRuntimeError for anything else.
int guarded_main(const std::string& program, const std::function<int()>& body);

}  // namespace ofn
