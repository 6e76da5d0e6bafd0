// ofn_bus_fuzz: puts the bus fuzz's messages (tests/fuzz: every channel of
// the channel table, every field of a valid message of its type made wrong
// in turn: cut short, behind a wrong fingerprint, a size or string length
// up to 2^31, NaN and Inf in every float, a stamp far in the past or the
// future, random bytes, oversized) on a live bus at a steady rate, and
// checks with the services' heartbeats that each one named on the command
// line lived through it (the same pid before and after) and counted what it
// refused.
//
// Before the flood it listens for every service's heartbeat and takes the
// flight's own messages as the seeds of their channels (a channel nobody
// publishes keeps a built-in seed); during it, stamps follow SIM_CLOCK (the
// wall clock on a bus without one). A fuzz message that its type's decode
// and validation would accept (an extreme but finite number, noise that
// lands well) is a forgery, not malformed input, and is withheld unless
// --send-valid; one whose only fault is a stamp far from now is sent, for
// the receivers' time checks. Every `--forgery-every` messages it
// also sends well-formed forgeries stamped with the simulation's own time,
// which a service must refuse: a SIM_CLOCK 1,000 s ahead, a CONTROL_STATUS
// saying DONE mid-flight, a REF_TRAJ at five times the speed limit and an
// ACTUATOR_CMD beyond the cyclic's range. (A forged MISSION that the
// controller refuses would still be taken by the planners: only an
// authenticated bus can stop that.)
//
// Exit code 0 when every expected service is alive with its pid and has
// refused more than before; 1 when one is not; 2 for bad input.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "ofn/actuator_cmd_t.hpp"
#include "ofn/bus_auth/authenticator.hpp"
#include "ofn/common/channel_table.hpp"
#include "ofn/common/channels.hpp"
#include "ofn/common/clock.hpp"
#include "ofn/common/command_line.hpp"
#include "ofn/common/node.hpp"
#include "ofn/control_status_t.hpp"
#include "ofn/fuzz/fuzz_cases.hpp"
#include "ofn/heartbeat_t.hpp"
#include "ofn/ref_traj_t.hpp"
#include "ofn/sim_clock_t.hpp"

namespace {

using Clock = std::chrono::steady_clock;
constexpr ofn::Utime kSecond = 1000000;

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

/// What the listening handle hears: the services' heartbeats, the
/// simulation's time, and (before the flood) the flight's own messages.
struct Listener {
  std::map<std::string, ofn::heartbeat_t> heartbeats;  // by service
  ofn::Utime sim_now = INT64_MIN;
  ofn::fuzz::Fuzzer* harvest = nullptr;  // set while seeds are taken
  std::map<std::string, Clock::time_point> offered;
  std::map<std::string, int> seeds_taken;  // by channel
  ofn::WallClock wall;
  int32_t own_pid = static_cast<int32_t>(::getpid());

  ofn::Utime now() const { return sim_now != INT64_MIN ? sim_now : wall.now(); }

  void on_heartbeat(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    ofn::heartbeat_t hb;
    if (!ofn::bus_auth::decode_payload(hb, rbuf->data, rbuf->data_size)) return;
    if (hb.pid == own_pid) return;  // this program's own fuzz
    heartbeats[hb.service] = hb;
  }

  void on_sim_clock(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    // The simulation's stamps move forward a little at a time; this
    // program's own (multicast loops them back) jump.
    ofn::sim_clock_t m;
    if (!ofn::bus_auth::decode_payload(m, rbuf->data, rbuf->data_size) || m.utime <= 0) return;
    if (sim_now == INT64_MIN || (m.utime >= sim_now && m.utime - sim_now < 10 * kSecond))
      sim_now = m.utime;
  }

  void on_any(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    if (harvest == nullptr) return;
    const auto last = offered.find(channel);
    if (last != offered.end() && Clock::now() - last->second < std::chrono::seconds(1)) return;
    offered[channel] = Clock::now();
    if (harvest->offer_seed(channel, static_cast<const uint8_t*>(rbuf->data), rbuf->data_size,
                            now(), 5 * kSecond, 4096))
      ++seeds_taken[channel];
  }
};

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
/// Returns how many were sent.
int publish_forgeries(lcm::LCM& lcm, ofn::Utime now) {
  namespace ch = ofn::channels;
  ofn::sim_clock_t clock{};
  clock.utime = now + 1000 * kSecond;
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
  return 4;
}

/// Handles what has arrived, at most `limit` messages.
void drain(lcm::LCM& lcm, int limit = 20000) {
  for (int i = 0; i < limit && lcm.handleTimeout(0) > 0; ++i) {
  }
}

std::string upper(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  ofn::CommandLine app{"ofn_bus_fuzz",
                       "publish the bus fuzz's messages on every channel and check that the "
                       "services live through them and count them"};
  std::string url = "udpm://239.255.76.67:7667?ttl=0";
  std::vector<std::string> services;
  int64_t messages = 5000;
  double rate = 2000.0;
  double wait = 30.0;
  double listen = 3.0, after = 4.0;
  int forgery_every = 100;
  uint64_t seed = 42;
  std::string report_path, valid_path;
  bool builtin_seeds = false, send_valid = false;
  app.add_option("--lcm-url", url, "LCM URL of the bus to attack");
  app.add_option("--messages", messages, "fuzz messages to send")
      ->check(CLI::Range(int64_t{1}, int64_t{1} << 40));
  app.add_option("--rate", rate, "messages per second")->check(CLI::Range(1.0, 1.0e6));
  app.add_option("--expect", services, "services that must stay alive and count rejections")
      ->required();
  app.add_option("--wait", wait,
                 "seconds to wait for every expected service's heartbeat before the flood")
      ->check(CLI::Range(0.0, 3600.0));
  app.add_option("--listen", listen,
                 "seconds to listen for the flight's own messages (the seeds) before the flood")
      ->check(CLI::Range(0.0, 3600.0));
  app.add_option("--after", after,
                 "seconds to listen for every service's heartbeat after the flood (they come "
                 "once a second of the simulation's time)")
      ->check(CLI::Range(1.0, 3600.0));
  app.add_option("--forgery-every", forgery_every,
                 "send the four well-formed forgeries after every N fuzz messages; 0 = never")
      ->check(CLI::Range(0, 1 << 30));
  app.add_option("--seed", seed, "seed of the random parts (the same seed, the same messages)");
  app.add_flag("--builtin-seeds", builtin_seeds,
               "mutate the built-in seed of every channel, not the flight's own messages");
  app.add_flag("--send-valid", send_valid,
               "also send what its type's decode and validation accept (an extreme but finite "
               "number, noise that lands well): forgeries for the command gate; stamps far "
               "from now are sent either way");
  app.add_option("--report", report_path,
                 "write what was sent and what each service counted to this JSON file "
                 "(default: none)");
  std::vector<std::string> only;
  app.add_option("--channel", only,
                 "fuzz only this channel of the channel table (a family by its prefix, "
                 "HEARTBEAT_); repeat for more (default: every channel)");
  app.add_option("--valid-log", valid_path,
                 "write every fuzz message that its type's decode and validation accept to "
                 "this file (a 2-byte channel length, the channel, a 4-byte length, the "
                 "bytes; big-endian), so that a recording can be judged without them "
                 "(default: none)");
  std::string sign_as, bus_keys;
  app.add_option("--sign-as", sign_as,
                 "sign the well-formed forgeries with this role's key from --bus-keys, as "
                 "if that host signed channels it may not publish (default: none, unsigned)");
  app.add_option("--bus-keys", bus_keys,
                 "keyring holding the --sign-as role's key (default: none)");
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;

  try {
    if (!sign_as.empty()) {
      // The stranger's own signer lets it sign anything; receivers judge.
      const std::string dir = bus_keys + "/";
      auto policy = ofn::bus_auth::PublishPolicy::load(dir + "policy.yaml");
      policy.allow(sign_as, "*");
      std::map<std::string, ofn::bus_auth::PublicKey> keys;
      for (const auto& role : policy.roles())
        keys[role] = ofn::bus_auth::read_public_key(dir + role + ".pub");
      // The clock goes with the signer (by value): this block ends before
      // it signs anything.
      const ofn::WallClock wall;
      g_forger = std::make_unique<ofn::bus_auth::Authenticator>(
          sign_as, ofn::bus_auth::read_secret_key(dir + sign_as + ".key"), keys, policy,
          [wall] { return wall.now(); });
    }
  } catch (const std::exception& e) {
    std::cerr << "ofn_bus_fuzz: " << e.what() << "\n";
    return 2;
  }

  // Every channel of the table; the heartbeat family on the expected
  // services' own channels and one of its own.
  std::map<std::string, std::vector<std::string>> families;
  for (const auto& entry : ofn::channel_table()) {
    if (!entry.prefix) continue;
    auto& names = families[entry.name];
    for (const auto& s : services) names.push_back(entry.name + upper(s));
    names.push_back(std::string(entry.name) + "FUZZ");
  }
  // Every channel has a generator, or none is fuzzed; --channel then picks.
  static std::vector<ofn::ChannelInfo> table = ofn::channel_table();
  std::optional<ofn::fuzz::Fuzzer> fuzzer;
  try {
    static const ofn::fuzz::Schema schema =
        ofn::fuzz::Schema::parse(ofn::fuzz::builtin_lcm_sources());
    fuzzer.emplace(schema, table, ofn::fuzz::message_supports(), families, seed);
    if (!only.empty()) {
      std::vector<ofn::ChannelInfo> picked;
      for (const auto& name : only) {
        const auto it = std::find_if(table.begin(), table.end(),
                                     [&](const ofn::ChannelInfo& c) { return name == c.name; });
        if (it == table.end()) {
          std::cerr << "ofn_bus_fuzz: --channel " << name << ": not in the channel table\n";
          return 2;
        }
        picked.push_back(*it);
      }
      fuzzer.reset();
      table = picked;
      fuzzer.emplace(schema, table, ofn::fuzz::message_supports(), families, seed);
    }
  } catch (const std::exception& e) {
    // A channel without a generator: the fuzz would leave it out.
    std::cerr << "ofn_bus_fuzz: " << e.what() << "\n";
    return 2;
  }

  lcm::LCM ear(url), mouth(url);
  if (!ear.good() || !mouth.good()) {
    std::cerr << "ofn_bus_fuzz: cannot open LCM at '" << url << "'\n";
    return 2;
  }
  Listener listener;
  ear.subscribe("HEARTBEAT_.*", &Listener::on_heartbeat, &listener);
  ear.subscribe(ofn::channels::kSimClock, &Listener::on_sim_clock, &listener);
  lcm::Subscription* everything = nullptr;
  if (!builtin_seeds) {
    listener.harvest = &*fuzzer;
    everything = ear.subscribe(".*", &Listener::on_any, &listener);
  }

  // Every expected service heard, then the flight's own messages for a
  // while: the pids and counters the flood is judged against.
  const auto wait_start = Clock::now();
  std::cout << "fuzz: waiting for the heartbeats of " << services.size() << " services"
            << std::endl;
  auto all_heard = [&] {
    for (const auto& s : services)
      if (!listener.heartbeats.count(s)) return false;
    return true;
  };
  while (!all_heard() && seconds_since(wait_start) < wait) ear.handleTimeout(100);
  const auto listen_start = Clock::now();
  while (seconds_since(listen_start) < listen) ear.handleTimeout(100);
  for (const auto& s : services)
    if (!listener.heartbeats.count(s)) {
      std::cout << "fuzz: " << s << ": no heartbeat in " << wait << " s; not started?" << std::endl;
      return 1;
    }
  listener.harvest = nullptr;
  if (everything) ear.unsubscribe(everything);
  const auto before = listener.heartbeats;
  std::string taken;
  for (const auto& [channel, n] : listener.seeds_taken) taken += " " + channel;
  std::cout << "fuzz: seeds from the flight on" << (taken.empty() ? " no channel" : taken)
            << "; built-in seeds on the others" << std::endl;

  std::ofstream valid_log;
  if (!valid_path.empty()) {
    valid_log.open(valid_path, std::ios::binary);
    if (!valid_log) {
      std::cerr << "ofn_bus_fuzz: cannot write " << valid_path << "\n";
      return 2;
    }
  }
  const auto record_valid = [&valid_log](const ofn::fuzz::FuzzMessage& m) {
    const auto put = [&valid_log](uint64_t v, int bytes) {
      for (int i = bytes - 1; i >= 0; --i) valid_log.put(static_cast<char>(v >> (8 * i)));
    };
    put(m.channel.size(), 2);
    valid_log.write(m.channel.data(), static_cast<std::streamsize>(m.channel.size()));
    put(m.bytes.size(), 4);
    valid_log.write(reinterpret_cast<const char*>(m.bytes.data()),
                    static_cast<std::streamsize>(m.bytes.size()));
  };

  // The flood, paced: message i goes at start + i / rate.
  std::map<std::string, int64_t> by_kind, by_channel, valid_by_kind, withheld_by_kind;
  int64_t sent = 0, forgeries = 0, bytes_sent = 0;
  const auto start = Clock::now();
  std::cout << "fuzz: flooding " << messages << " messages at " << rate << "/s on "
            << fuzzer->channels().size() << " channels" << std::endl;
  auto next_progress = start + std::chrono::seconds(10);
  while (sent < messages) {
    const auto due = std::min<int64_t>(
        messages, static_cast<int64_t>(std::floor(seconds_since(start) * rate)) + 1);
    while (sent < due) {
      const ofn::fuzz::FuzzMessage m = fuzzer->next(listener.now());
      if (m.valid && m.kind != ofn::fuzz::Kind::kStamp && !send_valid) {
        // A forgery, not malformed input: the command gate's to judge.
        ++withheld_by_kind[ofn::fuzz::kind_name(m.kind)];
        continue;
      }
      mouth.publish(m.channel, m.bytes.data(), static_cast<unsigned>(m.bytes.size()));
      ++by_kind[ofn::fuzz::kind_name(m.kind)];
      if (m.valid) {
        ++valid_by_kind[ofn::fuzz::kind_name(m.kind)];
        if (valid_log.is_open()) record_valid(m);
      }
      ++by_channel[m.channel];
      bytes_sent += static_cast<int64_t>(m.bytes.size());
      ++sent;
      if (forgery_every > 0 && sent % forgery_every == 0 && listener.sim_now != INT64_MIN)
        forgeries += publish_forgeries(mouth, listener.sim_now);
    }
    drain(ear);
    if (Clock::now() >= next_progress) {
      std::cout << "fuzz: sent " << sent << " of " << messages << " ("
                << std::lround(sent / seconds_since(start)) << "/s)" << std::endl;
      next_progress += std::chrono::seconds(10);
    }
    const auto next_due = start + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>((sent + 1) / rate));
    if (next_due > Clock::now())
      std::this_thread::sleep_until(
          std::min(next_due, Clock::now() + std::chrono::milliseconds(5)));
  }
  const double took = seconds_since(start);
  if (valid_log.is_open()) {
    valid_log.close();
    if (!valid_log) {
      std::cerr << "ofn_bus_fuzz: cannot write " << valid_path << "\n";
      return 2;
    }
  }
  int64_t valid = 0, withheld = 0;
  for (const auto& [kind, n] : valid_by_kind) valid += n;
  for (const auto& [kind, n] : withheld_by_kind) withheld += n;
  std::cout << "fuzz: flood done: " << sent << " messages (" << bytes_sent / 1000000.0
            << " MB) and " << forgeries << " forgeries in " << took << " s; " << valid
            << " of them valid to their type's decode and validation (far stamps); " << withheld
            << " other valid ones withheld (without --send-valid)" << std::endl;

  // Heartbeats come once a second of (simulated) time; listen long enough
  // for every service's next two.
  listener.heartbeats.clear();
  const auto after_start = Clock::now();
  while (seconds_since(after_start) < after) ear.handleTimeout(100);

  int failures = 0;
  nlohmann::json report;
  report["messages"] = sent;
  report["forgeries"] = forgeries;
  report["bytes"] = bytes_sent;
  report["seconds"] = took;
  report["rate"] = sent / took;
  report["by_kind"] = by_kind;
  report["by_channel"] = by_channel;
  report["valid_by_kind"] = valid_by_kind;
  report["withheld_by_kind"] = withheld_by_kind;
  report["seeds_from_flight"] = nlohmann::json::array();
  for (const auto& [channel, n] : listener.seeds_taken)
    report["seeds_from_flight"].push_back(channel);
  for (const auto& name : services) {
    const auto& b = before.at(name);
    nlohmann::json entry;
    entry["pid_before"] = b.pid;
    entry["rejected_before"] = b.rejected;
    entry["received_before"] = b.received;
    const auto it = listener.heartbeats.find(name);
    if (it == listener.heartbeats.end()) {
      std::cout << "fuzz: " << name << ": no heartbeat after the flood (dead?)" << std::endl;
      entry["alive"] = false;
      ++failures;
    } else {
      const auto& a = it->second;
      entry["alive"] = true;
      entry["pid_after"] = a.pid;
      entry["rejected_after"] = a.rejected;
      entry["received_after"] = a.received;
      entry["last_reject_reason"] = a.last_reject_reason;
      if (a.pid != b.pid) {
        std::cout << "fuzz: " << name << ": restarted during the flood (pid " << b.pid << " -> "
                  << a.pid << ")" << std::endl;
        ++failures;
      } else if (a.rejected <= b.rejected) {
        std::cout << "fuzz: " << name << ": alive but rejected nothing" << std::endl;
        ++failures;
      } else {
        std::cout << "fuzz: " << name << ": alive (pid " << a.pid << "), rejected "
                  << a.rejected - b.rejected << " (last: " << a.last_reject_reason << ")"
                  << std::endl;
      }
    }
    report["services"][name] = entry;
  }
  report["failures"] = failures;
  if (!report_path.empty()) {
    std::ofstream out(report_path);
    out << report.dump(2) << "\n";
    if (!out) {
      std::cerr << "ofn_bus_fuzz: cannot write " << report_path << "\n";
      return 2;
    }
  }
  return failures == 0 ? 0 : 1;
}
