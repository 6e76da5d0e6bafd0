#include "ofn/tools/flight_report.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "ofn/actuator_cmd_t.hpp"
#include "ofn/bus_auth/authenticator.hpp"
#include "ofn/bus_auth/trailer.hpp"
#include "ofn/common/channels.hpp"
#include "ofn/common/clock.hpp"
#include "ofn/common/mission_plan.hpp"
#include "ofn/common/ref_traj_sample.hpp"
#include "ofn/common/validate.hpp"
#include "ofn/control_status_t.hpp"
#include "ofn/cuboid_list_t.hpp"
#include "ofn/global_path_t.hpp"
#include "ofn/heartbeat_t.hpp"
#include "ofn/mission_t.hpp"
#include "ofn/narrow_passages_t.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/obstacle_grid_t.hpp"
#include "ofn/ref_traj_t.hpp"
#include "ofn/scan_world_t.hpp"
#include "ofn/solver_stats_t.hpp"
#include "ofn/tools/input_loss.hpp"
#include "ofn/world/world.hpp"

namespace ofn::report {
namespace {

/// The q-quantile (0..1, nearest rank) of the values; none when empty.
std::optional<double> percentile(std::vector<double> values, double q) {
  if (values.empty()) return std::nullopt;
  std::sort(values.begin(), values.end());
  const size_t i = std::min(
      values.size() - 1,
      static_cast<size_t>(std::ceil(q * values.size()) > 0 ? std::ceil(q * values.size()) - 1 : 0));
  return values[i];
}

// A message alone, or with its sequence trailer, the trailer of an
// authenticated bus, or both.
template <class Msg>
bool decode(const lcm::LogEvent& e, Msg& out) {
  return e.datalen >= 0 && bus_auth::decode_payload(out, e.data, static_cast<size_t>(e.datalen));
}

// A text field of a CSV row, quoted when it holds a separator, a quote or a
// line break (a heartbeat's service name comes from the bus, whoever sent it).
std::string csv_text(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + "\"";
}

std::ofstream open_csv(const std::filesystem::path& path, const std::string& header) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error("cannot write " + path.string());
  f << std::setprecision(10) << header << "\n";
  return f;
}

const char* kind_name(ObstacleSpec::Kind k) {
  switch (k) {
    case ObstacleSpec::Kind::kBox:
      return "box";
    case ObstacleSpec::Kind::kCylinder:
      return "cylinder";
    case ObstacleSpec::Kind::kTree:
      return "tree";
  }
  return "box";
}

/// A number for summary.json: null when absent or not finite.
nlohmann::ordered_json json_number(std::optional<double> v) {
  if (!v || !std::isfinite(*v)) return nullptr;
  return *v;
}

/// What a flight log holds, decoded, times in seconds from its first
/// NAV_STATE: what the summary is judged from.
struct FlightRecord {
  std::vector<NavSample> nav;
  std::vector<StatusSample> status;
  std::optional<mission_t> mission;
  std::optional<cuboid_list_t> last_cuboids;
  double last_cuboids_t = 0;
  size_t scan_points_seen = 0;
  int paths = 0;
  // Passages the RH optimiser found too narrow to fly (its last list).
  int narrow_passages = 0;
  std::vector<double> solve_times;
  std::map<int, int> solver_status_count;
  std::vector<TimeSpan> recovery;
  // ACTUATOR_CMD in the channel order of ControlStops.
  std::vector<std::array<double, 4>> commands;
  // Scan-to-plan latency: every map's stamp, and every step that planned.
  std::vector<double> map_stamps;
  std::vector<PlanStep> plan_steps;
  // What each service's heartbeats say it received, lost and duplicated.
  InputLossTally inputs;

  int count(int solver_status) const {
    const auto it = solver_status_count.find(solver_status);
    return it == solver_status_count.end() ? 0 : it->second;
  }
};

/// The per-channel CSV tables of a results folder, one writer each.
class CsvTables {
 public:
  explicit CsvTables(const std::filesystem::path& out)
      : nav_(open_csv(out / "nav_state.csv",
                      "t [s],north [m],east [m],down [m],vn [m/s],ve [m/s],vd [m/s],an [m/s^2],"
                      "ae [m/s^2],ad [m/s^2],roll [rad],pitch [rad],yaw [rad],p [rad/s],q [rad/s],"
                      "r [rad/s]")),
        status_(open_csv(out / "control_status.csv",
                         "t [s],mode,mission_id,active_waypoint,ref_n [m],ref_e [m],ref_d [m],"
                         "ref_vn [m/s],ref_ve [m/s],ref_vd [m/s],ref_an [m/s^2],ref_ae [m/s^2],"
                         "ref_ad [m/s^2],cmd_an [m/s^2],cmd_ae [m/s^2],cmd_ad [m/s^2],err_n [m],"
                         "err_e [m],err_d [m],yaw_ref [rad]")),
        command_(open_csv(out / "actuator_cmd.csv",
                          "t [s],collective [rad],lon_cyclic [rad],lat_cyclic [rad],pedal [rad]")),
        heartbeat_(open_csv(out / "heartbeats.csv",
                            "t [s],service,state,received,rejected,late,loop_time_mean [s],"
                            "loop_time_max [s],cpu_fraction,unauthenticated,lost,duplicated")),
        inputs_(open_csv(out / "inputs.csv",
                         "t [s],service,channel,received,lost,duplicated,unsequenced,publishers")),
        scan_(open_csv(out / "scan_points.csv", "t [s],north [m],east [m],down [m]")),
        path_(open_csv(out / "global_path.csv",
                       "t [s],seq,status,cost [m],north [m],east [m],down [m]")),
        ref_(open_csv(out / "ref_traj.csv",
                      "t [s],seq,mode,sample_t [s],north [m],east [m],down [m]")),
        stats_(open_csv(out / "solver_stats.csv",
                        "t [s],status,iterations,solve_time [s],max_violation,cost,warm_started")) {
  }

  void nav(const NavSample& s) {
    nav_ << s.t;
    row(nav_, {s.position, s.velocity, s.acceleration, s.euler, s.body_rates});
    nav_ << "\n";
  }
  void status(const StatusSample& s) {
    status_ << s.t << "," << s.mode << "," << s.mission_id << "," << s.active_waypoint;
    row(status_,
        {s.ref_position, s.ref_velocity, s.ref_acceleration, s.commanded_accel, s.position_error});
    status_ << "," << s.yaw_reference << "\n";
  }
  void command(double t, const actuator_cmd_t& m) {
    command_ << t << "," << m.collective << "," << m.lon_cyclic << "," << m.lat_cyclic << ","
             << m.pedal << "\n";
  }
  // Every scan point of a long flight would make a plot unreadable and a
  // file of hundreds of MB: every n-th point, up to a budget.
  void scan(double t, const scan_world_t& m, size_t* seen) {
    for (const auto& p : m.points) {
      if ((*seen)++ % kScanPointStride != 0 || scan_points_written_ >= kMaxScanPoints) continue;
      ++scan_points_written_;
      scan_ << t << "," << p[0] << "," << p[1] << "," << p[2] << "\n";
    }
  }
  void path(double t, int seq, const global_path_t& m) {
    for (const auto& p : m.points)
      path_ << t << "," << seq << "," << static_cast<int>(m.status) << "," << m.cost << "," << p[0]
            << "," << p[1] << "," << p[2] << "\n";
  }
  // Every n-th avoidance trajectory: a 10 Hz optimiser would otherwise
  // paint a solid band.
  void ref_traj(double t, double t0, const ref_traj_t& m) {
    if (m.mode == ref_traj_t::NOMINAL || ref_seen_++ % kRefTrajStride != 0) return;
    for (size_t i = 0; i < m.sample_time.size(); ++i)
      ref_ << t << "," << ref_seq_ << "," << static_cast<int>(m.mode) << ","
           << t0 + m.sample_time[i] << "," << m.position[i][0] << "," << m.position[i][1] << ","
           << m.position[i][2] << "\n";
    ++ref_seq_;
  }
  void solver_stats(double t, const solver_stats_t& m) {
    stats_ << t << "," << static_cast<int>(m.status) << "," << m.iterations << "," << m.solve_time
           << "," << m.max_constraint_violation << "," << m.cost << "," << (m.warm_started ? 1 : 0)
           << "\n";
  }
  // One row per heartbeat, lost and duplicated summed over its inputs;
  // one row per input in inputs.csv.
  void heartbeat(double t, const heartbeat_t& m) {
    int64_t lost = 0, duplicated = 0;
    for (const auto& in : m.inputs) {
      lost += in.lost;
      duplicated += in.duplicated;
      inputs_ << t << "," << csv_text(m.service) << "," << csv_text(in.channel) << ","
              << in.received << "," << in.lost << "," << in.duplicated << "," << in.unsequenced
              << "," << in.publishers << "\n";
    }
    heartbeat_ << t << "," << csv_text(m.service) << "," << csv_text(m.state) << "," << m.received
               << "," << m.rejected << "," << m.late << "," << m.loop_time_mean << ","
               << m.loop_time_max << "," << m.cpu_fraction << "," << m.unauthenticated << ","
               << lost << "," << duplicated << "\n";
  }

  static void waypoints(const std::filesystem::path& out, const std::optional<mission_t>& mission) {
    auto f =
        open_csv(out / "waypoints.csv", "index,north [m],east [m],down [m],capture_radius [m]");
    if (!mission) return;
    for (size_t i = 0; i < mission->waypoints.size(); ++i) {
      const auto& w = mission->waypoints[i];
      f << i << "," << w.position[0] << "," << w.position[1] << "," << w.position[2] << ","
        << w.capture_radius << "\n";
    }
  }
  /// The obstacle database as it stood at the end of the flight.
  static void cuboids(const std::filesystem::path& out, const FlightRecord& record) {
    auto f = open_csv(out / "cuboids.csv",
                      "t [s],id,min_n [m],min_e [m],min_d [m],max_n [m],max_e [m],max_d [m],"
                      "top_observed,confidence");
    if (!record.last_cuboids) return;
    for (const auto& c : record.last_cuboids->cuboids)
      f << record.last_cuboids_t << "," << c.id << "," << c.min_corner[0] << "," << c.min_corner[1]
        << "," << c.min_corner[2] << "," << c.max_corner[0] << "," << c.max_corner[1] << ","
        << c.max_corner[2] << "," << (c.top_observed ? 1 : 0) << "," << c.confidence << "\n";
  }

 private:
  static constexpr size_t kScanPointStride = 7;
  static constexpr size_t kMaxScanPoints = 300000;
  static constexpr int kRefTrajStride = 5;

  static void row(std::ofstream& f, std::initializer_list<Vec3> vs) {
    for (const auto& v : vs) f << "," << v.x() << "," << v.y() << "," << v.z();
  }

  std::ofstream nav_, status_, command_, heartbeat_, inputs_, scan_, path_, ref_, stats_;
  size_t scan_points_written_ = 0;
  int ref_seen_ = 0, ref_seq_ = 0;
};

/// Decodes each logged message into the record and its table.
class LogDecoder {
 public:
  LogDecoder(FlightRecord& record, CsvTables& tables, Utime t0)
      : record_(record), tables_(tables), t0_(t0) {}

  /// What became of a logged message.
  enum class Outcome { kRead, kUndecodable, kInvalid };

  /// Reads one message. One that fails the validation the services apply
  /// (a stranger's NaN position, say) is left out of the record and the
  /// tables, as the services left it out of the flight.
  Outcome handle(const std::string& channel, const lcm::LogEvent& e) {
    rejection_.clear();
    if (channel == channels::kNavState) return on<nav_state_t>(e, [this](auto& m) { nav(m); });
    if (channel == channels::kControlStatus)
      return on<control_status_t>(e, [this](auto& m) { control_status(m); });
    if (channel == channels::kActuatorCmd)
      return on<actuator_cmd_t>(e, [this](auto& m) {
        tables_.command(rel(m.utime), m);
        record_.commands.push_back({m.collective, m.lon_cyclic, m.lat_cyclic, m.pedal});
      });
    if (channel == channels::kScanWorld)
      return on<scan_world_t>(
          e, [this](auto& m) { tables_.scan(rel(m.utime), m, &record_.scan_points_seen); });
    if (channel == channels::kCuboids)
      return on<cuboid_list_t>(e, [this](auto& m) {
        record_.last_cuboids_t = rel(m.utime);
        record_.last_cuboids = std::move(m);
      });
    if (channel == channels::kGlobalPath)
      return on<global_path_t>(e,
                               [this](auto& m) { tables_.path(rel(m.utime), record_.paths++, m); });
    if (channel == channels::kNarrowPassages)
      return on<narrow_passages_t>(e,
                                   [this](auto& m) { record_.narrow_passages = m.num_passages; });
    if (channel == channels::kRefTraj)
      return on<ref_traj_t>(e, [this](auto& m) {
        // A plan sent as its spline alone is tabled as its receivers sample it.
        expand_ref_traj(m);
        tables_.ref_traj(rel(m.utime), rel(m.t0_utime), m);
      });
    if (channel == channels::kSolverStats)
      return on<solver_stats_t>(e, [this](auto& m) { solver_stats(m); });
    if (channel == channels::kObstacleGrid)
      return on<obstacle_grid_t>(e,
                                 [this](auto& m) { record_.map_stamps.push_back(rel(m.utime)); });
    if (channel == channels::kMission)
      return on<mission_t>(e, [this](auto& m) { record_.mission = m; });
    if (channel.rfind(channels::kHeartbeatPrefix, 0) == 0)
      return on<heartbeat_t>(e, [this](auto& m) {
        tables_.heartbeat(rel(m.utime), m);
        record_.inputs.heard(m);
      });
    return Outcome::kRead;  // a channel the report does not read
  }

  /// Why the last message handled was invalid.
  const std::string& rejection() const { return rejection_; }

 private:
  double rel(Utime t) const { return to_seconds(t - t0_); }

  template <class Msg, class Use>
  Outcome on(const lcm::LogEvent& e, Use use) {
    Msg m{};
    if (!decode(e, m)) return Outcome::kUndecodable;
    rejection_ = validate(m);
    if (!rejection_.empty()) return Outcome::kInvalid;
    use(m);
    return Outcome::kRead;
  }

  void nav(const nav_state_t& m) {
    NavSample s;
    s.t = rel(m.utime);
    s.position = to_vec3(m.position);
    s.velocity = to_vec3(m.velocity);
    s.acceleration = to_vec3(m.acceleration);
    s.euler = to_vec3(m.euler);
    s.body_rates = to_vec3(m.body_rates);
    record_.nav.push_back(s);
    tables_.nav(s);
  }

  void control_status(const control_status_t& m) {
    StatusSample s;
    s.t = rel(m.utime);
    s.mode = m.mode;
    s.mission_id = m.mission_id;
    s.active_waypoint = m.active_waypoint;
    s.ref_position = to_vec3(m.ref_position);
    s.ref_velocity = to_vec3(m.ref_velocity);
    s.ref_acceleration = to_vec3(m.ref_acceleration);
    s.commanded_accel = to_vec3(m.commanded_acceleration);
    s.position_error = to_vec3(m.position_error);
    s.yaw_reference = m.yaw_reference;
    record_.status.push_back(s);
    tables_.status(s);
  }

  void solver_stats(const solver_stats_t& m) {
    const double t = rel(m.utime);
    tables_.solver_stats(t, m);
    if (m.status != solver_stats_t::NOT_RUN) {
      ++record_.solver_status_count[m.status];
      record_.solve_times.push_back(m.solve_time);
    }
    // Steps that published a trajectory (a deferral leaves guidance on).
    if (m.status != solver_stats_t::NOT_RUN && m.status != solver_stats_t::DEFERRED &&
        m.map_utime > 0)
      record_.plan_steps.push_back({t, rel(m.map_utime)});
    // The dead-end recovery's steps, joined into spans (the optimiser
    // reports at 5-20 Hz; a gap of a second ends a span).
    const bool recovering =
        m.status == solver_stats_t::LOOKING_AROUND || m.status == solver_stats_t::NO_ROUTE ||
        m.message.rfind("escaping", 0) == 0 || m.message.rfind("climbing", 0) == 0;
    if (recovering) {
      auto& spans = record_.recovery;
      if (!spans.empty() && t - spans.back().end <= 1.0)
        spans.back().end = t;
      else
        spans.push_back({t, t});
    }
  }

  FlightRecord& record_;
  CsvTables& tables_;
  Utime t0_;
  std::string rejection_;
};

/// Counts what `handle` made of a message in `result`.
void count(LogDecoder& decoder, const lcm::LogEvent& e, ReportResult& result) {
  switch (decoder.handle(e.channel, e)) {
    case LogDecoder::Outcome::kRead:
      break;
    case LogDecoder::Outcome::kUndecodable:
      ++result.undecodable;
      break;
    case LogDecoder::Outcome::kInvalid:
      if (result.invalid++ == 0) result.first_invalid = e.channel + ": " + decoder.rejection();
      break;
  }
}

/// Checks each message of a recording of an authenticated bus as its
/// receivers did, at the (wall) time it was recorded: a stranger's message
/// in the recording is not the flight's.
class RecordingVerifier {
 public:
  explicit RecordingVerifier(const std::string& keyring_dir)
      : verifier_(bus_auth::load_verifier(keyring_dir, [this] { return recorded_at_; })) {}
  RecordingVerifier(const RecordingVerifier&) = delete;
  RecordingVerifier& operator=(const RecordingVerifier&) = delete;

  bus_auth::Opened open(const lcm::LogEvent& e) {
    recorded_at_ = e.timestamp;
    return verifier_.open(e.channel, e.data, e.datalen > 0 ? static_cast<size_t>(e.datalen) : 0);
  }

 private:
  int64_t recorded_at_ = 0;
  bus_auth::Verifier verifier_;
};

/// Reads the log (opened from `log_path`) into `record` and the tables.
/// Events before the first navigation sample have no time base yet; they
/// are kept until it comes.
/// With `verifier`, only authentic messages are read.
void read_log(lcm::LogFile& log, const std::string& log_path, RecordingVerifier* verifier,
              FlightRecord& record, CsvTables& tables, ReportResult& result) {
  std::optional<LogDecoder> decoder;
  std::vector<lcm::LogEvent> held;
  std::vector<std::vector<uint8_t>> held_data;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    ++result.events;
    // LCM's self-test, sent unsigned by every process as it starts, is
    // not a message of the flight's.
    if (verifier && e->channel != "LCM_SELF_TEST") {
      const bus_auth::Opened opened = verifier->open(*e);
      if (!opened.authentic) {
        if (result.unauthenticated++ == 0)
          result.first_unauthenticated = e->channel + ": " + opened.reason;
        continue;
      }
    }
    if (!decoder) {
      if (e->channel == channels::kNavState) {
        nav_state_t m{};
        if (decode(*e, m) && validate(m).empty()) decoder.emplace(record, tables, m.utime);
      }
      if (!decoder) {
        held.push_back(*e);
        held_data.emplace_back(static_cast<const uint8_t*>(e->data),
                               static_cast<const uint8_t*>(e->data) + e->datalen);
        continue;
      }
      for (size_t i = 0; i < held.size(); ++i) {
        held[i].data = held_data[i].data();
        count(*decoder, held[i], result);
      }
      held.clear();
    }
    count(*decoder, *e, result);
  }
  // Bad input (exit code 2), like an unreadable log.
  if (record.nav.empty())
    throw std::invalid_argument(log_path + ": no valid NAV_STATE messages in the log");
  // A multi-process log holds messages in arrival order.
  std::sort(record.map_stamps.begin(), record.map_stamps.end());
  std::sort(record.plan_steps.begin(), record.plan_steps.end(),
            [](const PlanStep& a, const PlanStep& b) { return a.published < b.published; });
}

/// What the summaries report beside the record: the course's facts and
/// what was judged from them.
struct Judged {
  std::string name;
  std::string log_path;
  Limits limits;
  std::optional<double> start_gate, finish_gate;
  PseudoControlBound pseudo_control_bound;
  std::optional<ControlSaturation> saturation;  // none without the controller's stops
  std::optional<Clearance> clearance;
  std::vector<double> scan_to_plan;
  DisplayUnit unit;
};

nlohmann::ordered_json summary_json(const FlightRecord& record, const Judged& j,
                                    const ReportResult& result,
                                    const std::optional<Scenario>& scenario) {
  using Json = nlohmann::ordered_json;
  const FlightSummary& s = result.summary;
  const auto& c = j.clearance;
  Json json;
  json["scenario"] = j.name;
  json["log"] = j.log_path;
  json["display_unit"] = j.unit.name;
  json["metres_per_unit"] = j.unit.metres_per_unit;
  json["limits"] = {{"max_speed", j.limits.max_speed},
                    {"max_accel", j.limits.max_accel},
                    {"max_vertical_speed", j.limits.max_vertical_speed}};
  json["gates"] = {{"start_x", json_number(j.start_gate)},
                   {"finish_x", json_number(j.finish_gate)}};
  json["gate_start_t"] = json_number(s.gate_start_time);
  json["gate_finish_t"] = json_number(s.gate_finish_time);
  json["gate_to_gate"] = json_number(s.gate_to_gate);
  json["reached_last_waypoint"] = s.reached_last_waypoint;
  // What the report left out of the flight, and why.
  json["messages_skipped"] = {
      {"undecodable", result.undecodable},
      {"invalid", result.invalid},
      {"unauthenticated", result.authenticated ? Json(result.unauthenticated) : Json(nullptr)}};
  // Per service and input channel, from the heartbeats (the last of each
  // process, added up over restarts): the publishers' sequence numbers.
  json["inputs"] = Json::array();
  for (const InputTotal& in : record.inputs.totals())
    json["inputs"].push_back({{"service", in.service},
                              {"channel", in.channel},
                              {"received", in.counts.received},
                              {"lost", in.counts.lost},
                              {"duplicated", in.counts.duplicated},
                              {"unsequenced", in.counts.unsequenced},
                              {"publishers", in.counts.publishers}});
  json["crossed_finish"] = s.crossed_finish;
  json["duration"] = s.duration;
  json["max_speed"] = s.max_speed;
  json["max_vertical_speed"] = s.max_vertical_speed;
  json["min_forward_speed"] = s.min_forward_speed;
  json["max_commanded_accel"] = s.max_commanded_accel;
  json["max_commanded_accel_fraction"] = s.max_commanded_accel_fraction;
  json["max_pseudo_control"] = s.max_pseudo_control;
  json["max_pseudo_control_horizontal"] = s.max_pseudo_control_horizontal;
  json["max_pseudo_control_vertical"] = s.max_pseudo_control_vertical;
  json["pseudo_control_bound"] = {{"horizontal", j.pseudo_control_bound.horizontal},
                                  {"vertical", j.pseudo_control_bound.vertical}};
  if (j.saturation)
    json["controls_at_stop"] = {
        {"samples", j.saturation->samples},     {"collective", j.saturation->share[0]},
        {"lon_cyclic", j.saturation->share[1]}, {"lat_cyclic", j.saturation->share[2]},
        {"pedal", j.saturation->share[3]},      {"cyclic", j.saturation->cyclic_share},
        {"any", j.saturation->any_share}};
  else
    json["controls_at_stop"] = nullptr;
  json["max_ref_position_jump"] = s.max_ref_position_jump;
  json["max_ref_position_jump_t"] = json_number(s.max_ref_position_jump_t);
  json["max_ref_velocity_jump"] = s.max_ref_velocity_jump;
  json["reference_resyncs"] = s.reference_resyncs;
  json["final_max_speed"] = json_number(s.final_max_speed);
  json["tracking_rms"] = s.tracking_rms;
  json["tracking_max"] = s.tracking_max;
  json["min_clearance"] = json_number(c ? std::optional<double>(c->distance) : std::nullopt);
  json["min_clearance_t"] = json_number(c ? std::optional<double>(c->t) : std::nullopt);
  json["min_clearance_surface"] = c ? Json(c->to_ground ? "ground" : "obstacle") : Json(nullptr);
  json["clearance_required"] = j.limits.clearance;
  json["rh_steps"] = record.solve_times.size();
  json["rh_solve_time_median"] = json_number(percentile(record.solve_times, 0.5));
  json["rh_solve_time_p99"] = json_number(percentile(record.solve_times, 0.99));
  json["rh_solve_time_max"] = json_number(percentile(record.solve_times, 1.0));
  json["rh_kept_previous"] = record.count(solver_stats_t::KEPT_PREVIOUS);
  json["rh_braking"] = record.count(solver_stats_t::BRAKING);
  json["rh_deferred"] = record.count(solver_stats_t::DEFERRED);
  json["rh_looking_around"] = record.count(solver_stats_t::LOOKING_AROUND);
  json["rh_no_route"] = record.count(solver_stats_t::NO_ROUTE);
  json["scan_to_plan_scans"] = j.scan_to_plan.size();
  json["scan_to_plan_median"] = json_number(percentile(j.scan_to_plan, 0.5));
  json["scan_to_plan_p99"] = json_number(percentile(j.scan_to_plan, 0.99));
  json["scan_to_plan_max"] = json_number(percentile(j.scan_to_plan, 1.0));
  json["recovery_time"] = s.recovery_time;
  json["narrow_passages"] = record.narrow_passages;
  json["outcome"] = to_string(result.verdict.outcome);
  json["success"] = result.verdict.success;
  json["failures"] = result.verdict.failures;
  // Metres, like every other length in this file (the plot scales them).
  json["obstacles"] = Json::array();
  if (scenario)
    for (const auto& o : scenario->obstacles)
      json["obstacles"].push_back({{"id", o.id},
                                   {"kind", kind_name(o.kind)},
                                   {"center", {o.north, o.east}},
                                   {"size", {o.length, o.width}},
                                   {"height", o.height},
                                   {"yaw", o.yaw},
                                   {"appear_time", o.appear_time},
                                   {"disappear_time", o.disappear_time}});
  return json;
}

/// "1 input", "2 inputs".
std::string count_of(size_t n, const std::string& thing) {
  return std::to_string(n) + " " + thing + (n == 1 ? "" : "s");
}

/// The loss line of the summary: none, or each input that lost or
/// duplicated messages on a line of its own. Nothing for a log whose
/// heartbeats carry no input counts (recorded before they did).
void input_loss_text(const std::vector<InputTotal>& inputs, std::ostringstream& t) {
  if (inputs.empty()) return;
  int64_t lost = 0, sent = 0;
  std::set<std::string> services;
  std::vector<const InputTotal*> shown;
  for (const InputTotal& in : inputs) {
    lost += in.counts.lost;
    sent += sequenced_sent(in.counts);
    services.insert(in.service);
    if (in.counts.lost > 0 || in.counts.duplicated > 0) shown.push_back(&in);
  }
  t << "  messages lost     : ";
  if (shown.empty()) {
    t << "none (" << count_of(inputs.size(), "input") << " of "
      << count_of(services.size(), "service") << ", by their heartbeats)\n";
    return;
  }
  t << lost << " of " << sent << " numbered messages, on " << shown.size() << " of "
    << count_of(inputs.size(), "input") << " of " << count_of(services.size(), "service")
    << " (by their heartbeats; inputs.csv):";
  for (const InputTotal* in : shown) t << "\n                      " << describe(*in);
  t << "\n";
}

std::string summary_text(const FlightRecord& record, const Judged& j, const ReportResult& result,
                         const std::filesystem::path& out) {
  const FlightSummary& s = result.summary;
  const std::string& unit = j.unit.name;
  const double k = j.unit.metres_per_unit;
  std::ostringstream t;
  t << std::fixed << std::setprecision(2);
  t << "Flight '" << j.name << "' (" << result.events << " logged messages, " << s.duration
    << " s of navigation data)\n";
  t << "  result            : "
    << (s.reached_last_waypoint ? "reached the last waypoint" : "did NOT reach the last waypoint");
  if (j.finish_gate)
    t << (s.crossed_finish ? ", crossed the finish gate" : ", did NOT cross the finish gate");
  t << "\n";
  t << "  outcome           : " << to_string(result.verdict.outcome);
  switch (result.verdict.outcome) {
    case Outcome::kSuccess:
      t << " (goal reached, no rule broken)";
      break;
    case Outcome::kSafeStop:
      t << " (goal not reached, no rule broken, hovering at the end: at most "
        << s.final_max_speed.value_or(0.0) / k << " " << unit << "/s over the last " << kHoverWindow
        << " s)";
      break;
    case Outcome::kFailure:
      for (const auto& f : result.verdict.failures) t << "\n                      " << f;
      break;
  }
  t << "\n";
  if (s.gate_to_gate)
    t << "  gate-to-gate time : " << *s.gate_to_gate << " s (x = " << *j.start_gate / k << " -> "
      << *j.finish_gate / k << " " << unit << ")\n";
  else if (j.start_gate || j.finish_gate)
    t << "  gate-to-gate time : n/a (a gate was not crossed)\n";
  t << "  max speed         : " << s.max_speed / k << " " << unit << "/s (limit "
    << j.limits.max_speed / k << ")\n";
  t << "  max reference acc : " << s.max_commanded_accel / k << " " << unit
    << "/s^2 = " << std::setprecision(0) << 100.0 * s.max_commanded_accel_fraction
    << std::setprecision(2) << " % of the " << j.limits.max_accel / k << " " << unit
    << "/s^2 limit (planned)\n";
  t << "  max pseudo-control: " << s.max_pseudo_control / k << " " << unit
    << "/s^2 (command plus feedback corrections); horizontal "
    << s.max_pseudo_control_horizontal / k << ", vertical " << s.max_pseudo_control_vertical / k
    << " (bounds " << j.pseudo_control_bound.horizontal / k << ", "
    << j.pseudo_control_bound.vertical / k << ")\n";
  if (j.saturation && j.saturation->samples > 0) {
    const ControlSaturation& c = *j.saturation;
    t << "  controls at a stop: " << std::setprecision(1) << 100.0 * c.cyclic_share
      << " % of the commands with a cyclic at its stop (longitudinal " << 100.0 * c.share[1]
      << ", lateral " << 100.0 * c.share[2] << "; collective " << 100.0 * c.share[0] << ", pedal "
      << 100.0 * c.share[3] << ")" << std::setprecision(2) << "\n";
  }
  t << "  reference jump    : " << s.max_ref_position_jump / k << " " << unit << ", "
    << s.max_ref_velocity_jump / k << " " << unit << "/s between samples (largest; position bound "
    << kMaxReferenceJump / k << " " << unit << ")";
  if (s.reference_resyncs > 0)
    t << "; " << s.reference_resyncs << " onto the vehicle (taken over from its state)";
  t << "\n";
  t << "  tracking error    : RMS " << s.tracking_rms / k << " " << unit << ", max "
    << s.tracking_max / k << " " << unit << "\n";
  if (j.clearance)
    t << "  least clearance   : " << j.clearance->distance / k << " " << unit
      << (j.clearance->to_ground ? " to the ground" : " to a real obstacle")
      << " at t = " << j.clearance->t << " s (required " << j.limits.clearance / k << ")\n";
  if (record.last_cuboids)
    t << "  obstacle database : " << record.last_cuboids->num_cuboids << " cuboids at the end, "
      << record.scan_points_seen << " LIDAR points mapped\n";
  const auto& solves = record.solve_times;
  if (!solves.empty()) {
    t << "  RH optimiser      : " << solves.size() << " steps, solve time median "
      << std::setprecision(1) << 1e3 * *percentile(solves, 0.5) << " ms, p99 "
      << 1e3 * *percentile(solves, 0.99) << " ms, max " << 1e3 * *percentile(solves, 1.0)
      << std::setprecision(2) << " ms; kept previous "
      << record.count(solver_stats_t::KEPT_PREVIOUS) << ", braking "
      << record.count(solver_stats_t::BRAKING) << ", deferred "
      << record.count(solver_stats_t::DEFERRED) << ", looking around "
      << record.count(solver_stats_t::LOOKING_AROUND) << ", no route "
      << record.count(solver_stats_t::NO_ROUTE) << "; " << std::setprecision(1) << s.recovery_time
      << " s in dead-end recovery";
    if (record.narrow_passages > 0)
      t << "; " << record.narrow_passages << " passage(s) too narrow to fly, routed round";
    t << "\n" << std::setprecision(2);
  } else {
    t << "  RH optimiser      : never engaged (nominal waypoint guidance throughout)\n";
  }
  const auto& latency = j.scan_to_plan;
  if (!latency.empty())
    t << "  scan to plan      : median " << std::setprecision(0) << 1e3 * *percentile(latency, 0.5)
      << " ms, p99 " << 1e3 * *percentile(latency, 0.99) << " ms, max "
      << 1e3 * *percentile(latency, 1.0) << " ms over " << latency.size()
      << " scans while avoiding (a scan's stamp to the first RH step on a map holding it)\n"
      << std::setprecision(2);
  if (record.paths > 0) t << "  global planner    : " << record.paths << " paths published\n";
  input_loss_text(record.inputs.totals(), t);
  if (result.undecodable)
    t << "  warning           : " << result.undecodable << " undecodable messages skipped\n";
  if (result.authenticated)
    t << "  bus               : authenticated; read only what the keyring's roles signed on "
      << "their channels (" << result.unauthenticated << " other messages skipped"
      << (result.unauthenticated ? ", the first " + result.first_unauthenticated : "") << ")\n";
  if (result.invalid)
    t << "  warning           : " << result.invalid
      << " invalid messages skipped, as the services skip them (first: " << result.first_invalid
      << ")\n";
  t << "  files             : " << out.string() << "/{nav_state,control_status,actuator_cmd,"
    << "heartbeats,inputs,waypoints,scan_points,cuboids,global_path,ref_traj,solver_stats}.csv, "
    << "summary.json\n";
  return t.str();
}

}  // namespace

ReportResult write_flight_report(const std::string& log_path, const std::string& out_dir,
                                 const std::optional<Scenario>& scenario,
                                 const PseudoControlBound& pseudo_control_bound,
                                 const std::string& bus_keyring,
                                 const std::optional<ControlStops>& control_stops) {
  namespace fs = std::filesystem;
  // Checked before any folder or file is made.
  lcm::LogFile log(log_path, "r");
  if (!log.good()) throw std::invalid_argument("cannot read LCM log " + log_path);
  std::optional<RecordingVerifier> verifier;
  if (!bus_keyring.empty()) verifier.emplace(bus_keyring);
  const fs::path out(out_dir);
  fs::create_directories(out);

  ReportResult result;
  result.authenticated = verifier.has_value();
  FlightRecord record;
  {
    CsvTables tables(out);
    read_log(log, log_path, verifier ? &*verifier : nullptr, record, tables, result);
  }
  CsvTables::waypoints(out, record.mission);
  CsvTables::cuboids(out, record);

  Judged j;
  j.log_path = log_path;
  j.name = scenario ? scenario->name : (record.mission ? record.mission->name : "flight");
  if (record.mission) j.limits = limits_from(record.mission->limits);
  j.start_gate = scenario ? scenario->start_gate : std::nullopt;
  j.finish_gate = scenario ? scenario->finish_gate : std::nullopt;
  j.pseudo_control_bound = pseudo_control_bound;
  if (control_stops) j.saturation = control_saturation(record.commands, *control_stops);
  j.scan_to_plan = scan_to_plan_latencies(record.map_stamps, record.plan_steps);
  j.unit = DisplayUnit{scenario ? scenario->display_unit : "m",
                       scenario ? scenario->metres_per_unit : 1.0};
  // True clearance: distance from the flown path to the real surfaces, the
  // obstacles present at that time and the ground, over the whole flight.
  if (scenario)
    j.clearance =
        least_clearance(record.nav, world::World(scenario->obstacles, scenario->ground_altitude));
  result.min_clearance = j.clearance ? std::optional<double>(j.clearance->distance) : std::nullopt;
  result.summary = analyse_flight(record.nav, record.status, j.limits, j.start_gate, j.finish_gate,
                                  record.recovery);
  result.verdict = judge_flight(result.summary, j.limits, pseudo_control_bound,
                                result.min_clearance, j.finish_gate.has_value(), j.unit);

  std::ofstream(out / "summary.json") << summary_json(record, j, result, scenario).dump(2) << "\n";
  result.text = summary_text(record, j, result, out);
  std::ofstream(out / "summary.txt") << result.text;
  return result;
}

}  // namespace ofn::report
