// The flight report on logs written here: a short hover on the open course,
// what its summary.json and tables hold, and input that must not break them.

#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "ofn/actuator_cmd_t.hpp"
#include "ofn/bus_auth/authenticator.hpp"
#include "ofn/common/channels.hpp"
#include "ofn/common/clock.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/control_status_t.hpp"
#include "ofn/heartbeat_t.hpp"
#include "ofn/narrow_passages_t.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/solver_stats_t.hpp"
#include "ofn/tools/flight_report.hpp"

namespace ofn::report {
namespace {

namespace fs = std::filesystem;

const std::string kOpenScenario = std::string(OFN_SOURCE_DIR) + "/sim/scenarios/open.yaml";

class FlightReport : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        fs::temp_directory_path() /
        ("ofn-flight-report-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  template <class Msg>
  static std::vector<uint8_t> encoded(const Msg& m) {
    std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
    m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    return bytes;
  }
  static void write_bytes(lcm::LogFile& log, const std::string& channel, std::vector<uint8_t> bytes,
                          Utime t) {
    lcm::LogEvent e{};
    e.timestamp = t;
    e.channel = channel;
    e.datalen = static_cast<int32_t>(bytes.size());
    e.data = bytes.data();
    log.writeEvent(&e);
  }
  template <class Msg>
  static void write(lcm::LogFile& log, const std::string& channel, const Msg& m, Utime t) {
    write_bytes(log, channel, encoded(m), t);
  }

  /// A hover of `seconds` at `here`: NAV_STATE at 100 Hz, CONTROL_STATUS at
  /// 50 Hz (mode HOLD), and a heartbeat from a service with a hostile name.
  std::string hover_log(const std::string& name, const Vec3& here, double seconds) {
    const std::string path = (dir_ / name).string();
    lcm::LogFile log(path, "w");
    EXPECT_TRUE(log.good());
    const Utime t0 = 1000 * kMicrosPerSecond;
    for (int i = 0; i <= static_cast<int>(seconds * 100); ++i) {
      const Utime t = t0 + i * 10000;
      nav_state_t nav{};
      nav.utime = t;
      nav.frame = "NED";
      for (int k = 0; k < 3; ++k) nav.position[k] = here[k];
      nav.quaternion[0] = 1.0;
      write(log, channels::kNavState, nav, t);
      if (i % 2 == 0) {
        control_status_t s{};
        s.utime = t;
        s.mode = control_status_t::HOLD;
        s.mission_id = -1;
        s.active_waypoint = -1;
        for (int k = 0; k < 3; ++k) s.ref_position[k] = here[k];
        write(log, channels::kControlStatus, s, t);
      }
    }
    heartbeat_t hb{};
    hb.utime = t0;
    hb.service = "a \"quoted\", service\nname";
    hb.state = "running";
    write(log, std::string(channels::kHeartbeatPrefix) + "MAPPER", hb, t0);
    return path;
  }

  static nlohmann::json read_json(const fs::path& path) {
    std::ifstream f(path);
    return nlohmann::json::parse(f);
  }

  static size_t lines_of(const fs::path& path) {
    std::ifstream f(path);
    size_t n = 0;
    for (std::string line; std::getline(f, line);) ++n;
    return n;
  }

  fs::path dir_;
};

TEST_F(FlightReport, AHoverIsTabledAndSummarised) {
  const Scenario open = load_scenario(kOpenScenario);
  const Vec3 start = open.start_position;
  const std::string log = hover_log("hover.lcm", start, 3.0);
  const fs::path out = dir_ / "report";
  const ReportResult result = write_flight_report(log, out.string(), open, PseudoControlBound{});

  EXPECT_EQ(result.undecodable, 0u);
  EXPECT_EQ(result.events, 301u + 151u + 1u);
  EXPECT_NEAR(result.summary.duration, 3.0, 1e-9);
  EXPECT_FALSE(result.summary.reached_last_waypoint);
  // Headers name their units; one header line, then one row per message.
  std::ifstream nav_table(out / "nav_state.csv");
  std::string header;
  std::getline(nav_table, header);
  EXPECT_EQ(header.rfind("t [s],north [m],east [m],down [m],vn [m/s],", 0), 0u) << header;
  EXPECT_EQ(lines_of(out / "nav_state.csv"), 1u + 301u);
  EXPECT_EQ(lines_of(out / "control_status.csv"), 1u + 151u);
  // The heartbeat's name quoted as CSV: its line break inside the quotes.
  EXPECT_EQ(lines_of(out / "heartbeats.csv"), 1u + 2u);
  std::ifstream heartbeats(out / "heartbeats.csv");
  const std::string table((std::istreambuf_iterator<char>(heartbeats)),
                          std::istreambuf_iterator<char>());
  EXPECT_NE(table.find(",\"a \"\"quoted\"\", service\nname\",running,"), std::string::npos)
      << table;

  const nlohmann::json json = read_json(out / "summary.json");
  EXPECT_EQ(json.at("scenario"), open.name);
  EXPECT_EQ(json.at("log"), log);
  EXPECT_EQ(json.at("outcome"), to_string(result.verdict.outcome));
  EXPECT_EQ(json.at("success"), result.verdict.success);
  EXPECT_DOUBLE_EQ(json.at("duration").get<double>(), result.summary.duration);
  EXPECT_EQ(json.at("rh_steps"), 0);
  // Nothing measured is null, not a number that is not one.
  EXPECT_TRUE(json.at("gate_to_gate").is_null());
  EXPECT_TRUE(json.at("rh_solve_time_median").is_null());
  ASSERT_TRUE(json.at("min_clearance").is_number());
  EXPECT_NEAR(json.at("min_clearance").get<double>(), *result.min_clearance, 1e-12);
  EXPECT_EQ(json.at("failures").size(), result.verdict.failures.size());
  EXPECT_EQ(json.at("obstacles").size(), open.obstacles.size());
}

// Numbered messages read as before; the heartbeats' input counts are
// tabled, totalled over a restart and shown when something was lost.
TEST_F(FlightReport, LossTheHeartbeatsCountIsTabledAndShown) {
  const Scenario open = load_scenario(kOpenScenario);
  const std::string path = (dir_ / "numbered.lcm").string();
  {
    lcm::LogFile log(path, "w");
    ASSERT_TRUE(log.good());
    const Utime t0 = 1000 * kMicrosPerSecond;
    for (int i = 0; i <= 200; ++i) {
      nav_state_t nav{};
      nav.utime = t0 + i * 10000;
      nav.frame = "NED";
      for (int k = 0; k < 3; ++k) nav.position[k] = open.start_position[k];
      nav.quaternion[0] = 1.0;
      auto bytes = encoded(nav);
      bus_auth::append_sequence_trailer(bytes, {99, static_cast<uint64_t>(i + 1)});
      write_bytes(log, channels::kNavState, bytes, nav.utime);
    }
    auto beat = [&](int32_t pid, int64_t received, int64_t lost, Utime t) {
      heartbeat_t hb{};
      hb.utime = t;
      hb.service = "mapper";
      hb.pid = pid;
      hb.state = "running";
      channel_counts_t in{};
      in.channel = channels::kNavState;
      in.received = received;
      in.lost = lost;
      in.publishers = 1;
      channel_counts_t quiet = in;
      quiet.channel = channels::kScanWorld;
      quiet.lost = 0;
      hb.inputs = {in, quiet};
      hb.num_inputs = 2;
      write(log, std::string(channels::kHeartbeatPrefix) + "MAPPER", hb, t);
    };
    beat(10, 90, 10, t0 + kMicrosPerSecond);
    beat(11, 45, 5, t0 + 2 * kMicrosPerSecond);  // restarted: counts from zero
  }
  const fs::path out = dir_ / "report";
  const ReportResult result = write_flight_report(path, out.string(), open, PseudoControlBound{});
  EXPECT_EQ(result.undecodable, 0u);
  EXPECT_NEAR(result.summary.duration, 2.0, 1e-9);
  // One row per heartbeat and input; the heartbeat's row sums its inputs.
  EXPECT_EQ(lines_of(out / "inputs.csv"), 1u + 4u);
  std::ifstream heartbeats(out / "heartbeats.csv");
  std::string header, first;
  std::getline(heartbeats, header);
  std::getline(heartbeats, first);
  EXPECT_EQ(header.substr(header.size() - std::string(",lost,duplicated").size()),
            ",lost,duplicated");
  EXPECT_EQ(first.substr(first.size() - 5), ",10,0") << first;
  // Totals over both processes.
  const nlohmann::json json = read_json(out / "summary.json");
  ASSERT_EQ(json.at("inputs").size(), 2u);
  EXPECT_EQ(json.at("inputs")[0].at("channel"), channels::kNavState);
  EXPECT_EQ(json.at("inputs")[0].at("received"), 135);
  EXPECT_EQ(json.at("inputs")[0].at("lost"), 15);
  EXPECT_EQ(json.at("inputs")[1].at("lost"), 0);
  EXPECT_NE(result.text.find("messages lost     : 15 of 285 numbered messages, on 1 of 2 inputs "
                             "of 1 service (by their heartbeats; inputs.csv):"),
            std::string::npos)
      << result.text;
  EXPECT_NE(result.text.find("mapper NAV_STATE: 15 of 150 lost (10.0 %)"), std::string::npos)
      << result.text;
  EXPECT_EQ(result.text.find("mapper SCAN_WORLD"), std::string::npos) << result.text;
}

TEST_F(FlightReport, NoLossSaysNoneAndALogWithoutCountsSaysNothing) {
  const Scenario open = load_scenario(kOpenScenario);
  // hover_log's heartbeat carries no inputs (as one recorded before they did).
  const std::string plain = hover_log("hover.lcm", open.start_position, 1.0);
  const ReportResult before =
      write_flight_report(plain, (dir_ / "before").string(), open, PseudoControlBound{});
  EXPECT_EQ(before.text.find("messages lost"), std::string::npos) << before.text;
  EXPECT_TRUE(read_json(dir_ / "before" / "summary.json").at("inputs").empty());
  {
    lcm::LogFile log(plain, "a");
    heartbeat_t hb{};
    hb.utime = 1000 * kMicrosPerSecond;
    hb.service = "controller";
    hb.state = "running";
    channel_counts_t in{};
    in.channel = channels::kNavState;
    in.received = 100;
    in.publishers = 1;
    hb.inputs = {in};
    hb.num_inputs = 1;
    write(log, std::string(channels::kHeartbeatPrefix) + "CONTROLLER", hb, hb.utime);
  }
  const ReportResult after =
      write_flight_report(plain, (dir_ / "after").string(), open, PseudoControlBound{});
  EXPECT_NE(after.text.find("messages lost     : none (1 input of 1 service, by their "
                            "heartbeats)"),
            std::string::npos)
      << after.text;
}

// With the controller's stops the summary says how much of the flight a
// control was at one; without them it says nothing (null), not zero.
TEST_F(FlightReport, ControlsAtAStopAreSharesOfTheCommands) {
  const Scenario open = load_scenario(kOpenScenario);
  const std::string path = hover_log("hover.lcm", open.start_position, 1.0);
  {
    lcm::LogFile log(path, "a");
    ASSERT_TRUE(log.good());
    const Utime t0 = 1000 * kMicrosPerSecond;
    for (int i = 0; i < 100; ++i) {
      actuator_cmd_t m{};
      m.utime = t0 + i * 10000;
      m.collective = 0.1;
      m.lon_cyclic = i < 25 ? 0.16 : 0.02;   // the first quarter at the forward stop
      m.lat_cyclic = i >= 90 ? -0.16 : 0.0;  // the last tenth at the left stop
      write(log, channels::kActuatorCmd, m, m.utime);
    }
  }
  const ControlStops stops{{-0.05, -0.16, -0.16, -0.40}, {0.30, 0.16, 0.16, 0.40}};
  const ReportResult result =
      write_flight_report(path, (dir_ / "report").string(), open, PseudoControlBound{}, "", stops);
  const nlohmann::json json = read_json(dir_ / "report" / "summary.json");
  const nlohmann::json& at_stop = json.at("controls_at_stop");
  EXPECT_EQ(at_stop.at("samples"), 100);
  EXPECT_DOUBLE_EQ(at_stop.at("lon_cyclic").get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(at_stop.at("lat_cyclic").get<double>(), 0.10);
  EXPECT_DOUBLE_EQ(at_stop.at("cyclic").get<double>(), 0.35);
  EXPECT_DOUBLE_EQ(at_stop.at("collective").get<double>(), 0.0);
  EXPECT_NE(
      result.text.find("controls at a stop: 35.0 % of the commands with a cyclic at its stop"),
      std::string::npos)
      << result.text;

  write_flight_report(path, (dir_ / "no-stops").string(), open, PseudoControlBound{});
  EXPECT_TRUE(read_json(dir_ / "no-stops" / "summary.json").at("controls_at_stop").is_null());
}

// The time in dead-end recovery counts the steps the optimiser marks as
// such: looks (LOOKING_AROUND), escapes ("escaping: ...") and climbs to
// look ("climbing: ..."), each a span of steps with no gap over 1 s;
// ordinary solved steps do not count.
TEST_F(FlightReport, RecoveryTimeCountsLooksEscapesAndClimbs) {
  const Scenario open = load_scenario(kOpenScenario);
  const std::string path = hover_log("recovery.lcm", open.start_position, 20.0);
  {
    lcm::LogFile log(path, "a");
    ASSERT_TRUE(log.good());
    const Utime t0 = 1000 * kMicrosPerSecond;
    auto steps = [&](double from, double to, int8_t status, const std::string& message) {
      for (double t = from; t <= to + 1e-9; t += 0.1) {
        solver_stats_t m{};
        m.utime = t0 + static_cast<Utime>(t * kMicrosPerSecond);
        m.status = status;
        m.message = message;
        write(log, channels::kSolverStats, m, m.utime);
      }
    };
    steps(1.0, 2.0, solver_stats_t::SOLVED, "solved");
    steps(3.0, 5.0, solver_stats_t::LOOKING_AROUND, "recovery: looking around");
    steps(5.1, 8.0, solver_stats_t::SOLVED, "climbing: solved: climbing");
    steps(10.0, 12.0, solver_stats_t::BRAKING, "escaping: braking");
    steps(14.0, 15.0, solver_stats_t::SOLVED, "solved");
    // The optimiser's list of passages too narrow to fly: the last says two.
    for (int count : {0, 1, 2}) {
      narrow_passages_t m{};
      m.utime = t0 + (9 + count) * kMicrosPerSecond;
      m.frame = "NED";
      for (int i = 0; i < count; ++i) {
        m.centre.push_back({40.0 + 10 * i, 0.0, -30.0});
        m.radius.push_back(6.5);
        m.half_height.push_back(3.0);
      }
      m.num_passages = count;
      write(log, channels::kNarrowPassages, m, m.utime);
    }
  }
  const ReportResult result =
      write_flight_report(path, (dir_ / "report").string(), open, PseudoControlBound{});
  // 3.0-8.0 (a look, then a climb) and 10.0-12.0 (an escape).
  EXPECT_NEAR(result.summary.recovery_time, 7.0, 1e-3);
  const nlohmann::json json = read_json(dir_ / "report" / "summary.json");
  EXPECT_EQ(json.at("narrow_passages"), 2);
}

// A scenario named with quotes, backslashes and a line break, a log path
// with a quote, failure lines quoting them: summary.json stays JSON and
// says them as they are.
TEST_F(FlightReport, NamesWithQuotesStayJson) {
  Scenario open = load_scenario(kOpenScenario);
  open.name = "the \"hard\" course \\ 2\nsecond line";
  const std::string log = hover_log("it's \"a\" log.lcm", open.start_position, 1.0);
  const fs::path out = dir_ / "report";
  write_flight_report(log, out.string(), open, PseudoControlBound{});
  const nlohmann::json json = read_json(out / "summary.json");
  EXPECT_EQ(json.at("scenario"), open.name);
  EXPECT_EQ(json.at("log"), log);
}

// A stranger's NAV_STATE in the recording (a bus fuzz's: north not a
// number, down 0 m, stamped 0) is not the vehicle's: it is left out, counted
// and named, and it does not put the vehicle on the ground.
TEST_F(FlightReport, InvalidMessagesAreLeftOutAndCounted) {
  const Scenario open = load_scenario(kOpenScenario);
  const std::string path = hover_log("hover.lcm", open.start_position, 1.0);
  {
    lcm::LogFile log(path, "a");
    ASSERT_TRUE(log.good());
    nav_state_t forged{};
    forged.frame = "NED";
    forged.position[0] = std::numeric_limits<double>::quiet_NaN();
    forged.position[2] = 0.0;
    forged.quaternion[0] = 1.0;
    for (int i = 0; i < 3; ++i) write(log, channels::kNavState, forged, 1001 * kMicrosPerSecond);
  }
  const ReportResult clean =
      write_flight_report(hover_log("clean.lcm", open.start_position, 1.0),
                          (dir_ / "clean").string(), open, PseudoControlBound{});
  const ReportResult result =
      write_flight_report(path, (dir_ / "report").string(), open, PseudoControlBound{});
  EXPECT_EQ(result.invalid, 3u);
  EXPECT_EQ(clean.invalid, 0u);
  EXPECT_EQ(result.first_invalid.rfind("NAV_STATE: position not finite", 0), 0u)
      << result.first_invalid;
  EXPECT_NE(result.text.find("3 invalid messages skipped"), std::string::npos) << result.text;
  ASSERT_TRUE(result.min_clearance && clean.min_clearance);
  EXPECT_DOUBLE_EQ(*result.min_clearance, *clean.min_clearance);
  EXPECT_GT(*result.min_clearance, 20.0);
  EXPECT_EQ(lines_of(dir_ / "report" / "nav_state.csv"), 1u + 101u);
}

// A recording of an authenticated bus read with its keyring: a DONE signed
// with the ground station's key (which may not publish CONTROL_STATUS) and
// unsigned navigation are a stranger's, left out, so the hover is not taken
// for a finished mission. Without the keyring the forged DONE counts.
TEST_F(FlightReport, WithTheKeyringOnlyWhatTheRolesSignedIsRead) {
  namespace auth = bus_auth;
  const fs::path keys = dir_ / "keyring";
  fs::create_directories(keys);
  std::ofstream(keys / "policy.yaml")
      << "publishers:\n  onboard1: [NAV_STATE, CONTROL_STATUS]\n  gcs: [MISSION]\n";
  std::map<std::string, auth::KeyPair> pairs;
  std::map<std::string, auth::PublicKey> public_keys;
  for (const char* role : {"onboard1", "gcs"}) {
    pairs[role] = auth::generate_key_pair();
    public_keys[role] = pairs[role].public_key;
    auth::write_public_key((keys / (std::string(role) + ".pub")).string(), pairs[role].public_key);
  }
  Utime wall = 1'800'000'000'000'000;  // the recording host's clock
  const auto policy = auth::PublishPolicy::load((keys / "policy.yaml").string());
  auth::Authenticator onboard1("onboard1", pairs["onboard1"].secret_key, public_keys, policy,
                               [&wall] { return wall; });
  // The stranger's own signer signs anything with the ground station's key.
  auto anything = policy;
  anything.allow("gcs", "*");
  auth::Authenticator stranger("gcs", pairs["gcs"].secret_key, public_keys, anything,
                               [&wall] { return wall; });
  const auto record = [&](lcm::LogFile& log, auth::Authenticator* signer,
                          const std::string& channel, const auto& m) {
    std::vector<uint8_t> bytes = encoded(m);
    if (signer) signer->seal(channel, bytes);
    write_bytes(log, channel, std::move(bytes), wall);
  };
  const Scenario open = load_scenario(kOpenScenario);
  const std::string path = (dir_ / "signed.lcm").string();
  {
    lcm::LogFile log(path, "w");
    ASSERT_TRUE(log.good());
    for (int i = 0; i <= 100; ++i, wall += 10000) {
      nav_state_t nav{};
      nav.utime = i * 10000;
      nav.frame = "NED";
      for (int k = 0; k < 3; ++k) nav.position[k] = open.start_position[k];
      nav.quaternion[0] = 1.0;
      record(log, &onboard1, channels::kNavState, nav);
      control_status_t status{};
      status.utime = nav.utime;
      status.mode = control_status_t::HOLD;
      status.mission_id = -1;
      status.active_waypoint = -1;
      for (int k = 0; k < 3; ++k) status.ref_position[k] = open.start_position[k];
      record(log, &onboard1, channels::kControlStatus, status);
      if (i == 50) {
        status.mode = control_status_t::DONE;
        status.mission_id = 1;
        record(log, &stranger, channels::kControlStatus, status);
        nav.position[2] = 0.0;  // on the ground, unsigned
        record(log, nullptr, channels::kNavState, nav);
      }
    }
  }
  const ReportResult trusting =
      write_flight_report(path, (dir_ / "trusting").string(), open, PseudoControlBound{});
  EXPECT_TRUE(trusting.summary.reached_last_waypoint);
  EXPECT_FALSE(trusting.authenticated);

  const ReportResult result = write_flight_report(path, (dir_ / "report").string(), open,
                                                  PseudoControlBound{}, keys.string());
  EXPECT_TRUE(result.authenticated);
  EXPECT_FALSE(result.summary.reached_last_waypoint);
  EXPECT_EQ(result.unauthenticated, 2u);
  EXPECT_EQ(result.first_unauthenticated, "CONTROL_STATUS: role 'gcs' may not publish here");
  ASSERT_TRUE(result.min_clearance);
  EXPECT_GT(*result.min_clearance, 20.0);
  EXPECT_EQ(lines_of(dir_ / "report" / "nav_state.csv"), 1u + 101u);
  EXPECT_NE(result.text.find("bus               : authenticated"), std::string::npos)
      << result.text;
  const nlohmann::json json = read_json(dir_ / "report" / "summary.json");
  EXPECT_EQ(json.at("messages_skipped").at("unauthenticated"), 2);
  EXPECT_TRUE(read_json(dir_ / "trusting" / "summary.json")
                  .at("messages_skipped")
                  .at("unauthenticated")
                  .is_null());
  // A keyring that cannot be read is bad input.
  EXPECT_THROW(write_flight_report(path, (dir_ / "out").string(), open, PseudoControlBound{},
                                   (dir_ / "no-keyring").string()),
               std::invalid_argument);
}

TEST_F(FlightReport, ALogWithoutNavigationIsBadInput) {
  const std::string path = (dir_ / "empty.lcm").string();
  {
    lcm::LogFile log(path, "w");
    ASSERT_TRUE(log.good());
  }
  EXPECT_THROW(write_flight_report(path, (dir_ / "out").string(), std::nullopt, {}),
               std::invalid_argument);
  // Nothing but a stranger's navigation is no navigation.
  const std::string forged_path = (dir_ / "forged.lcm").string();
  {
    lcm::LogFile log(forged_path, "w");
    ASSERT_TRUE(log.good());
    nav_state_t forged{};
    forged.frame = "NED";
    forged.quaternion[0] = 2.0;
    write(log, channels::kNavState, forged, 0);
  }
  EXPECT_THROW(write_flight_report(forged_path, (dir_ / "out").string(), std::nullopt, {}),
               std::invalid_argument);
  EXPECT_THROW(write_flight_report((dir_ / "missing.lcm").string(), (dir_ / "out").string(),
                                   std::nullopt, {}),
               std::invalid_argument);
}

}  // namespace
}  // namespace ofn::report
