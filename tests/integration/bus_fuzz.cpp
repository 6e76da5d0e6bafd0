// Publishes garbage on every channel of the bus (random bytes, each message
// type filled with NaN or with absurd sizes, and valid encodings with a
// hostile int32 written over a random field: negative or huge array counts
// and string lengths behind a valid fingerprint), then listens to the
// heartbeats and reports each service's rejection counter. Alongside the
// garbage it sends well-formed forgeries stamped with the simulation's own
// time, each of which a service must refuse: a SIM_CLOCK 1,000 s ahead, a
// CONTROL_STATUS saying DONE mid-flight, a REF_TRAJ at five times the speed
// limit and an ACTUATOR_CMD beyond the cyclic's range. (A forged MISSION
// that the controller refuses would still be taken by the planners: only an
// authenticated bus can stop that.) Exits 0 when every service named on the
// command line is still alive and has rejected something.

#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>

#include "ofn/actuator_cmd_t.hpp"
#include "ofn/bus_auth/authenticator.hpp"
#include "ofn/common/channels.hpp"
#include "ofn/common/clock.hpp"
#include "ofn/common/command_line.hpp"
#include "ofn/common/node.hpp"
#include "ofn/control_status_t.hpp"
#include "ofn/heartbeat_t.hpp"
#include "ofn/mission_t.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/ref_traj_t.hpp"
#include "ofn/sim_clock_t.hpp"

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// `m` encoded, with a hostile int32 (big-endian) written at a random
/// 4-byte-aligned offset after the fingerprint: wherever it lands on an
/// array count or a string length, the decoder must fail cleanly.
template <class Msg>
std::vector<uint8_t> with_hostile_int32(const Msg& m, std::mt19937& rng) {
  std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  static const int32_t kHostile[] = {-1, -2147483647 - 1, 0, 1 << 26, 2147483647};
  if (bytes.size() < 12) return bytes;
  const size_t slots = (bytes.size() - 8) / 4;
  const size_t at = 8 + 4 * std::uniform_int_distribution<size_t>(0, slots - 1)(rng);
  const auto value = static_cast<uint32_t>(kHostile[std::uniform_int_distribution<int>(0, 4)(rng)]);
  for (int i = 0; i < 4; ++i) bytes[at + i] = static_cast<uint8_t>(value >> (24 - 8 * i));
  return bytes;
}

/// The simulation time from SIM_CLOCK, ignoring this program's own forged
/// stamps (multicast loops them back).
void on_sim_clock(const lcm::ReceiveBuffer* rbuf, const std::string&, ofn::Utime* sim_now) {
  ofn::sim_clock_t m;
  if (!ofn::bus_auth::decode_payload(m, rbuf->data, rbuf->data_size)) return;
  if (*sim_now == INT64_MIN || (m.utime >= *sim_now && m.utime - *sim_now < 100 * 1000000LL))
    *sim_now = m.utime;
}

void on_heartbeat(const lcm::ReceiveBuffer* rbuf, const std::string&,
                  std::map<std::string, ofn::heartbeat_t>* seen) {
  ofn::heartbeat_t hb;
  if (ofn::bus_auth::decode_payload(hb, rbuf->data, rbuf->data_size)) (*seen)[hb.service] = hb;
}

/// Signs the forgeries when set (--sign-as): a stranger who holds one
/// host's key and signs what that host may not publish.
std::unique_ptr<ofn::bus_auth::Authenticator> g_forger;

template <class Msg>
void publish_forgery(lcm::LCM& lcm, const std::string& channel, const Msg& msg) {
  if (!g_forger) {
    lcm.publish(channel, &msg);
    return;
  }
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  g_forger->seal(channel, bytes);
  lcm.publish(channel, bytes.data(), static_cast<unsigned>(bytes.size()));
}

/// Well-formed messages that pass validation and must still be refused.
void publish_forgeries(lcm::LCM& lcm, ofn::Utime now) {
  namespace ch = ofn::channels;
  ofn::sim_clock_t clock{};
  clock.utime = now + 1000 * 1000000LL;
  clock.real_time_factor = 1.0;
  publish_forgery(lcm, ch::kSimClock, clock);

  ofn::control_status_t done{};
  done.utime = now;
  done.mode = ofn::control_status_t::DONE;
  done.mission_id = 1;
  publish_forgery(lcm, ch::kControlStatus, done);

  ofn::ref_traj_t fast{};
  fast.utime = now;
  fast.t0_utime = now;
  fast.frame = "NED";
  fast.mode = ofn::ref_traj_t::AVOIDANCE;
  fast.num_samples = 2;
  fast.sample_time = {0.0, 2.0};
  fast.position = {{0, 0, -6}, {30, 0, -6}};
  fast.velocity = {{15, 0, 0}, {15, 0, 0}};
  fast.acceleration = {{0, 0, 0}, {0, 0, 0}};
  publish_forgery(lcm, ch::kRefTraj, fast);

  ofn::actuator_cmd_t cmd{};
  cmd.utime = now;
  cmd.collective = 0.1;
  cmd.lon_cyclic = 0.9;
  publish_forgery(lcm, ch::kActuatorCmd, cmd);
}

}  // namespace

int main(int argc, char** argv) {
  ofn::CommandLine app{"ofn_bus_fuzz",
                       "publish garbage on every channel and check that services reject it"};
  std::string url = "udpm://239.255.76.67:7667?ttl=0";
  std::vector<std::string> services;
  int rounds = 200;
  app.add_option("--lcm-url", url, "LCM URL of the bus to attack");
  app.add_option("--rounds", rounds, "garbage messages per channel and kind");
  app.add_option("--expect", services, "services that must stay alive and count rejections")
      ->required();
  std::string sign_as, bus_keys;
  app.add_option("--sign-as", sign_as,
                 "sign the well-formed forgeries with this role's key from --bus-keys, as "
                 "if that host signed channels it may not publish (default: none, unsigned)");
  app.add_option("--bus-keys", bus_keys,
                 "keyring holding the --sign-as role's key (default: none)");
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;
  if (!sign_as.empty()) {
    // The stranger's own signer lets it sign anything; receivers judge.
    const std::string dir = bus_keys + "/";
    auto policy = ofn::bus_auth::PublishPolicy::load(dir + "policy.yaml");
    policy.allow(sign_as, "*");
    std::map<std::string, ofn::bus_auth::PublicKey> keys;
    for (const auto& role : policy.roles())
      keys[role] = ofn::bus_auth::read_public_key(dir + role + ".pub");
    // The clock goes with the signer (by value): this block ends before it
    // signs anything.
    const ofn::WallClock wall;
    g_forger = std::make_unique<ofn::bus_auth::Authenticator>(
        sign_as, ofn::bus_auth::read_secret_key(dir + sign_as + ".key"), keys, policy,
        [wall] { return wall.now(); });
  }

  lcm::LCM lcm(url);
  if (!lcm.good()) return 2;
  std::map<std::string, ofn::heartbeat_t> seen;
  lcm.subscribeFunction("HEARTBEAT_.*", &on_heartbeat, &seen);
  ofn::Utime sim_now = INT64_MIN;
  lcm.subscribeFunction(ofn::channels::kSimClock, &on_sim_clock, &sim_now);

  namespace ch = ofn::channels;
  const std::vector<std::string> channels = {ch::kNavState,    ch::kActuatorCmd,      ch::kSimClock,
                                             ch::kMission,     ch::kVirtualObstacles, ch::kLidarRaw,
                                             ch::kScanWorld,   ch::kObstacleGrid,     ch::kCuboids,
                                             ch::kGlobalPath,  ch::kNarrowPassages,   ch::kRefTraj,
                                             ch::kSolverStats, ch::kControlStatus};
  std::mt19937 rng(42);
  std::uniform_int_distribution<int> byte(0, 255), length(0, 600);

  ofn::nav_state_t nav{};
  nav.frame = "NED";
  for (int i = 0; i < 3; ++i) nav.position[i] = kNaN;
  nav.quaternion[0] = 1;
  ofn::actuator_cmd_t cmd{};
  cmd.collective = kNaN;
  ofn::sim_clock_t clock{};
  clock.real_time_factor = kNaN;
  ofn::mission_t mission{};
  mission.frame = "NED";
  mission.cruise_speed = kNaN;
  ofn::ref_traj_t traj{};
  traj.frame = "NED";
  traj.num_samples = 2;
  traj.sample_time = {0.0, kNaN};
  traj.position = traj.velocity = traj.acceleration = {{0, 0, 0}, {0, 0, 0}};
  ofn::control_status_t status{};
  status.ref_position[0] = kNaN;

  for (int r = 0; r < rounds; ++r) {
    for (const auto& c : channels) {
      std::vector<uint8_t> junk(static_cast<size_t>(length(rng)));
      for (auto& b : junk) b = static_cast<uint8_t>(byte(rng));
      lcm.publish(c, junk.data(), static_cast<unsigned>(junk.size()));
    }
    lcm.publish(ch::kNavState, &nav);
    lcm.publish(ch::kActuatorCmd, &cmd);
    lcm.publish(ch::kSimClock, &clock);
    lcm.publish(ch::kMission, &mission);
    lcm.publish(ch::kRefTraj, &traj);
    lcm.publish(ch::kControlStatus, &status);
    const auto hostile = [&](const std::string& channel, const auto& m) {
      const std::vector<uint8_t> bytes = with_hostile_int32(m, rng);
      lcm.publish(channel, bytes.data(), static_cast<unsigned>(bytes.size()));
    };
    hostile(ch::kNavState, nav);
    hostile(ch::kMission, mission);
    hostile(ch::kRefTraj, traj);
    hostile(ch::kControlStatus, status);
    if (sim_now != INT64_MIN) publish_forgeries(lcm, sim_now);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    while (lcm.handleTimeout(0) > 0) {
    }
  }
  // Heartbeats come once a second of (simulated) time; listen long enough.
  seen.clear();
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(4);
  while (std::chrono::steady_clock::now() < until) lcm.handleTimeout(100);

  int failures = 0;
  for (const auto& name : services) {
    auto it = seen.find(name);
    if (it == seen.end()) {
      std::cout << "fuzz: " << name << ": no heartbeat after the flood (dead?)\n";
      ++failures;
    } else if (it->second.rejected <= 0) {
      std::cout << "fuzz: " << name << ": alive but rejected nothing\n";
      ++failures;
    } else {
      std::cout << "fuzz: " << name << ": alive, rejected " << it->second.rejected
                << " (last: " << it->second.last_reject_reason << ")\n";
    }
  }
  return failures == 0 ? 0 : 1;
}
