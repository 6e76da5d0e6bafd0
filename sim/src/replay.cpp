#include "ofn/sim/replay.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#include <lcm/lcm-cpp.hpp>

#include "ofn/bus_auth/trailer.hpp"
#include "ofn/common/channels.hpp"
#include "ofn/common/clock.hpp"
#include "ofn/common/config.hpp"
#include "ofn/common/node.hpp"
#include "ofn/cuboid_list_t.hpp"
#include "ofn/global_path_t.hpp"
#include "ofn/narrow_passages_t.hpp"
#include "ofn/obstacle_grid_t.hpp"
#include "ofn/ref_traj_t.hpp"
#include "ofn/scan_world_t.hpp"
#include "ofn/sim_clock_t.hpp"
#include "ofn/solver_stats_t.hpp"

namespace ofn::sim {
namespace {

using Bytes = std::vector<uint8_t>;

struct ServiceSpec {
  std::string name;
  std::vector<std::string> inputs;
  std::vector<std::string> outputs;  // compared channels
};

// Who consumes and publishes what, as the service classes subscribe and
// publish (heartbeats aside).
const std::vector<ServiceSpec>& service_specs() {
  static const std::vector<ServiceSpec> specs = {
      {"sensor_interface",
       {channels::kNavState, channels::kLidarRaw},
       {channels::kScanWorld, channels::kScannerStatus}},
      {"mapper",
       {channels::kScanWorld, channels::kNavState},
       {channels::kObstacleGrid, channels::kCuboids}},
      {"global_planner",
       {channels::kNavState, channels::kMission, channels::kCuboids, channels::kNarrowPassages},
       {channels::kGlobalPath}},
      {"rh_optimizer",
       {channels::kNavState, channels::kMission, channels::kObstacleGrid, channels::kGlobalPath,
        channels::kScanWorld},
       {channels::kRefTraj, channels::kSolverStats, channels::kNarrowPassages}},
  };
  return specs;
}

const ServiceSpec& spec_of(const std::string& name) {
  for (const auto& spec : service_specs())
    if (spec.name == name) return spec;
  throw ReplayInputError("unknown service '" + name + "'");
}

// Every message of the project starts with LCM's 8-byte type hash and then
// its int64 utime, big-endian.
Utime utime_of(const Bytes& bytes) {
  if (bytes.size() < 16) return INT64_MIN;
  uint64_t v = 0;
  for (int i = 8; i < 16; ++i) v = (v << 8) | bytes[static_cast<size_t>(i)];
  return static_cast<Utime>(v);
}

template <class Msg>
bool decode(const Bytes& bytes, Msg& msg) {
  return bus_auth::decode_payload(msg, bytes.data(), bytes.size());
}

template <class Msg>
Bytes encode(const Msg& msg) {
  Bytes out(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(out.data(), 0, static_cast<int>(out.size()));
  return out;
}

constexpr double kStructural = std::numeric_limits<double>::infinity();

struct MessageDifference {
  double value = 0.0;  // SI units of the fields
  double stamp = 0.0;  // s
};

// Largest absolute difference over numeric fields; a structural difference
// (sizes, enums, ids, text) makes it infinite.
class FieldDifference {
 public:
  void number(double a, double b) {
    if (std::isnan(a) && std::isnan(b)) return;
    const double d = std::fabs(a - b);
    largest_ = std::isnan(d) ? kStructural : std::max(largest_, d);
  }
  // Stamps are kept apart: in a real-time log they differ by scheduling
  // delays that say nothing about the content.
  void time(int64_t a, int64_t b) {
    stamp_ = std::max(stamp_, std::fabs(to_seconds(a) - to_seconds(b)));
  }
  template <class T>
  void same(const T& a, const T& b) {
    if (!(a == b)) largest_ = kStructural;
  }
  template <class Array>
  void numbers(const Array& a, const Array& b, size_t n) {
    for (size_t i = 0; i < n; ++i) number(a[i], b[i]);
  }
  template <class Rows>
  void rows(const Rows& a, const Rows& b) {
    if (a.size() != b.size()) {
      largest_ = kStructural;
      return;
    }
    for (size_t i = 0; i < a.size(); ++i) numbers(a[i], b[i], a[i].size());
  }
  template <class T>
  void values(const std::vector<T>& a, const std::vector<T>& b) {
    if (a.size() != b.size()) {
      largest_ = kStructural;
      return;
    }
    numbers(a, b, a.size());
  }
  MessageDifference largest() const { return {largest_, stamp_}; }

 private:
  double largest_ = 0.0;
  double stamp_ = 0.0;
};

MessageDifference difference(const scan_world_t& a, const scan_world_t& b) {
  FieldDifference d;
  d.time(a.utime, b.utime);
  d.same(a.scan_index, b.scan_index);
  d.same(a.frame, b.frame);
  d.numbers(a.sensor_origin, b.sensor_origin, 3);
  d.rows(a.points, b.points);
  d.rows(a.free_ray_ends, b.free_ray_ends);
  d.same(a.num_rejected, b.num_rejected);
  return d.largest();
}

MessageDifference difference(const obstacle_grid_t& a, const obstacle_grid_t& b) {
  FieldDifference d;
  d.time(a.utime, b.utime);
  d.same(a.frame, b.frame);
  d.numbers(a.origin, b.origin, 2);
  d.number(a.resolution, b.resolution);
  d.number(a.safety_margin, b.safety_margin);
  d.same(a.rows, b.rows);
  d.same(a.cols, b.cols);
  d.values(a.top_altitude, b.top_altitude);
  return d.largest();
}

MessageDifference difference(const cuboid_list_t& a, const cuboid_list_t& b) {
  FieldDifference d;
  d.time(a.utime, b.utime);
  d.same(a.frame, b.frame);
  d.same(a.cuboids.size(), b.cuboids.size());
  for (size_t i = 0; i < std::min(a.cuboids.size(), b.cuboids.size()); ++i) {
    const cuboid_t& p = a.cuboids[i];
    const cuboid_t& q = b.cuboids[i];
    d.same(p.id, q.id);
    d.numbers(p.min_corner, q.min_corner, 3);
    d.numbers(p.max_corner, q.max_corner, 3);
    d.same(p.top_observed, q.top_observed);
    d.number(p.confidence, q.confidence);
    d.time(p.last_seen_utime, q.last_seen_utime);
  }
  return d.largest();
}

MessageDifference difference(const global_path_t& a, const global_path_t& b) {
  FieldDifference d;
  d.time(a.utime, b.utime);
  d.same(a.frame, b.frame);
  d.same(a.status, b.status);
  d.number(a.cost, b.cost);
  d.rows(a.points, b.points);
  return d.largest();
}

MessageDifference difference(const narrow_passages_t& a, const narrow_passages_t& b) {
  FieldDifference d;
  d.time(a.utime, b.utime);
  d.same(a.frame, b.frame);
  d.same(a.mission_id, b.mission_id);
  d.rows(a.centre, b.centre);
  d.values(a.radius, b.radius);
  d.values(a.half_height, b.half_height);
  return d.largest();
}

MessageDifference difference(const ref_traj_t& a, const ref_traj_t& b) {
  FieldDifference d;
  d.time(a.utime, b.utime);
  d.time(a.t0_utime, b.t0_utime);
  d.same(a.frame, b.frame);
  d.same(a.mode, b.mode);
  d.same(a.degree, b.degree);
  d.values(a.knots, b.knots);
  d.rows(a.control_points, b.control_points);
  d.values(a.sample_time, b.sample_time);
  d.rows(a.position, b.position);
  d.rows(a.velocity, b.velocity);
  d.rows(a.acceleration, b.acceleration);
  return d.largest();
}

MessageDifference difference(const solver_stats_t& a, const solver_stats_t& b) {
  FieldDifference d;
  d.time(a.utime, b.utime);
  d.same(a.status, b.status);
  d.same(a.message, b.message);
  d.number(a.iterations, b.iterations);
  d.number(a.max_constraint_violation, b.max_constraint_violation);
  d.number(a.cost, b.cost);
  d.same(a.warm_started, b.warm_started);
  d.same(a.guidance_clear, b.guidance_clear);
  d.same(a.mission_id, b.mission_id);
  d.same(a.active_waypoint, b.active_waypoint);
  return d.largest();
}

template <class Msg>
MessageDifference decoded_difference(const Bytes& recorded, const Bytes& replayed) {
  Msg a, b;
  if (!decode(recorded, a) || !decode(replayed, b)) return {kStructural, 0.0};
  return difference(a, b);
}

MessageDifference message_difference(const std::string& channel, const Bytes& recorded,
                                     const Bytes& replayed) {
  if (channel == channels::kScanWorld) return decoded_difference<scan_world_t>(recorded, replayed);
  if (channel == channels::kObstacleGrid)
    return decoded_difference<obstacle_grid_t>(recorded, replayed);
  if (channel == channels::kCuboids) return decoded_difference<cuboid_list_t>(recorded, replayed);
  if (channel == channels::kGlobalPath)
    return decoded_difference<global_path_t>(recorded, replayed);
  if (channel == channels::kNarrowPassages)
    return decoded_difference<narrow_passages_t>(recorded, replayed);
  if (channel == channels::kRefTraj) return decoded_difference<ref_traj_t>(recorded, replayed);
  if (channel == channels::kSolverStats)
    return decoded_difference<solver_stats_t>(recorded, replayed);
  return {kStructural, 0.0};
}

// The payload alone: the sequence trailer names the publisher, which is
// another one in the replay. solve_time is the wall time a solve took: it
// never repeats, so it is left out of the byte comparison.
Bytes comparable(const std::string& channel, const Bytes& bytes) {
  if (channel != channels::kSolverStats) {
    const size_t payload = bus_auth::payload_bytes(bytes.data(), bytes.size());
    return Bytes(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(payload));
  }
  solver_stats_t stats;
  if (!decode(bytes, stats)) return bytes;
  stats.solve_time = 0.0;
  return encode(stats);
}

// A replayed output waiting for the point where the recording has it.
struct HeldMessage {
  Utime key = 0;
  Bytes bytes;
  Utime produced = 0;
};

// What pairs a replayed message with its recording whatever the order they
// turn up in. SCAN_WORLD and OBSTACLE_GRID carry the scan's time, which the
// data fixes; the other outputs are stamped with the clock when a timer or
// handler ran, which a service following SIM_CLOCK in real time reads late
// by however long it took to get round to it. Those are paired by their
// place in the channel's sequence when the replay follows SIM_CLOCK.
enum class PairingKey { kUtime, kSequence };

struct ChannelState {
  ChannelComparison comparison;
  PairingKey pairing = PairingKey::kUtime;
  size_t producer = 0;                     // index into Session::services_
  std::deque<HeldMessage> held;            // produced, not yet delivered
  std::multimap<Utime, Bytes> unpaired;    // delivered, no recording paired yet
  std::multimap<Utime, Bytes> unanswered;  // recorded, no replayed message yet
};

struct ReplayedService {
  std::string name;
  std::set<std::string> inputs;
  std::unique_ptr<lcm::LCM> lcm;
  Node* node = nullptr;
};

class Session;

struct CaptureContext {
  Session* session = nullptr;
  size_t service = 0;
};

class Session {
 public:
  Session(const ReplayOptions& options, bool follow_sim_clock)
      : options_(options), follow_sim_clock_(follow_sim_clock) {
    // The outputs of a replayed service are held until the recording says
    // they were delivered; the hold only matters when a message of the
    // recording never comes. In a lockstep log everything published in a
    // step is delivered within the step.
    hold_ = follow_sim_clock ? to_utime(1.0) : 0;
    services_.reserve(options.services.size());
    captures_.reserve(options.services.size());
    for (const std::string& name : options.services) add_service(name);
  }

  void on_event(const lcm::LogEvent& event) {
    ++result_.events_read;
    if (first_time_ == INT64_MIN) first_time_ = event.timestamp;
    last_time_ = event.timestamp;
    // A log of an authenticated flight: the replay runs on an open bus and
    // compares payloads, so the authentication trailer is left off (the
    // sequence trailer stays: the replayed services count by it).
    auto size = static_cast<unsigned>(event.datalen);
    if (bus_auth::ends_with_trailer(event.data, size)) size -= bus_auth::kTrailerBytes;
    if (follow_sim_clock_) {
      if (event.channel == channels::kSimClock) {
        sim_clock_t tick;
        if (bus_auth::decode_payload(tick, event.data, size)) step_to(tick.utime);
      }
    } else {
      step_to(event.timestamp);
    }
    if (auto it = channels_.find(event.channel); it != channels_.end()) {
      const auto* data = static_cast<const uint8_t*>(event.data);
      on_recorded_output(it->second, Bytes(data, data + size));
      return;
    }
    if (replayed_heartbeats_.count(event.channel)) return;
    write(event.channel, event.data, size, event.timestamp);
    bool consumed = false;
    for (auto& service : services_) {
      if (!service.inputs.count(event.channel)) continue;
      deliver(service, event.channel, event.data, size);
      consumed = true;
    }
    if (consumed) ++result_.inputs_fed;
  }

  ReplayResult finish() {
    for (auto& [channel, state] : channels_) {
      while (!state.held.empty()) release_front(state, false);
    }
    for (const auto& spec_name : options_.services) {
      for (const auto& channel : spec_of(spec_name).outputs) {
        ChannelState& state = channels_.at(channel);
        state.comparison.missing = static_cast<int64_t>(state.unanswered.size());
        state.comparison.extra = static_cast<int64_t>(state.unpaired.size());
        result_.channels.push_back(state.comparison);
      }
    }
    for (const auto& service : services_)
      result_.rejected_inputs.emplace_back(service.name, service.node->counters().rejected);
    result_.clock = follow_sim_clock_ ? "SIM_CLOCK messages" : "log timestamps";
    result_.tolerance = options_.tolerance;
    result_.stamp_tolerance = options_.stamp_tolerance;
    if (first_time_ != INT64_MIN) result_.duration = to_seconds(last_time_ - first_time_);
    return result_;
  }

  void open_replayed_log(const std::string& path) {
    replayed_log_ = std::make_unique<lcm::LogFile>(path, "w");
    if (!replayed_log_->good()) throw ReplayInputError("cannot write the replayed log " + path);
  }

 private:
  void add_service(const std::string& name) {
    const ServiceSpec& spec = spec_of(name);
    ReplayedService service;
    service.name = name;
    service.inputs.insert(spec.inputs.begin(), spec.inputs.end());
    service.lcm = std::make_unique<lcm::LCM>("memq://");
    if (!service.lcm->good()) throw std::runtime_error("cannot open memq:// LCM");
    captures_.push_back(std::make_unique<CaptureContext>(CaptureContext{this, services_.size()}));
    for (const std::string& channel : spec.outputs) {
      service.lcm->subscribeFunction(channel, &Session::on_capture, captures_.back().get());
      ChannelState& state = channels_[channel];
      state.comparison.channel = channel;
      state.producer = services_.size();
      const bool stamped_by_scan = channel == channels::kScanWorld ||
                                   channel == channels::kScannerStatus ||
                                   channel == channels::kObstacleGrid;
      state.pairing =
          follow_sim_clock_ && !stamped_by_scan ? PairingKey::kSequence : PairingKey::kUtime;
    }
    const std::string heartbeat = heartbeat_channel(name);
    service.lcm->subscribeFunction(heartbeat, &Session::on_capture, captures_.back().get());
    replayed_heartbeats_.insert(heartbeat);

    const auto& c = options_.configs;
    lcm::LCM& lcm = *service.lcm;
    if (name == "sensor_interface") {
      sensor_.emplace(lcm, clock_, c.sensor_interface);
      service.node = &sensor_->node();
    } else if (name == "mapper") {
      mapper_.emplace(lcm, clock_, c.mapper);
      service.node = &mapper_->node();
    } else if (name == "global_planner") {
      planner_.emplace(lcm, clock_, c.global_planner);
      service.node = &planner_->node();
    } else {
      optimizer_.emplace(lcm, clock_, c.rh_optimizer);
      service.node = &optimizer_->node();
    }
    services_.push_back(std::move(service));
  }

  // As the lockstep scheduler: every timer deadline of the replayed
  // services up to `t` is a step of its own, timers fire in chain order
  // before anything stamped with the step's time is delivered.
  void step_to(Utime t) {
    if (!clock_.valid()) {
      clock_.update(t);
      fire_timers();
    }
    if (follow_sim_clock_) {
      // A service following SIM_CLOCK only ever sees the message's times:
      // its timers fire late, at the first tick past their deadline.
      if (t > clock_.now()) {
        clock_.update(t);
        release_overdue();
        fire_timers();
      }
      return;
    }
    while (true) {
      Utime next = INT64_MAX;
      for (const auto& service : services_) next = std::min(next, service.node->next_deadline());
      if (next > t) break;
      if (next > clock_.now()) clock_.update(next);
      release_overdue();
      fire_timers();
    }
    if (t > clock_.now()) clock_.update(t);
    release_overdue();
  }

  void fire_timers() {
    for (auto& service : services_) {
      service.node->fire_due_timers();
      drain(service);
    }
  }

  static void drain(ReplayedService& service) {
    while (service.lcm->handleTimeout(0) > 0) {
    }
  }

  void deliver(ReplayedService& service, const std::string& channel, const void* data,
               unsigned size) {
    service.lcm->publish(channel, data, size);
    drain(service);
  }

  static void on_capture(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                         CaptureContext* context) {
    const auto* data = static_cast<const uint8_t*>(rbuf->data);
    context->session->on_output(channel, Bytes(data, data + rbuf->data_size));
  }

  void on_output(const std::string& channel, Bytes bytes) {
    auto it = channels_.find(channel);
    if (it == channels_.end()) {  // a heartbeat: nobody replayed consumes it
      write(channel, bytes.data(), static_cast<int32_t>(bytes.size()), clock_.now());
      return;
    }
    ChannelState& state = it->second;
    const Utime key =
        state.pairing == PairingKey::kSequence ? state.comparison.replayed : utime_of(bytes);
    ++state.comparison.replayed;
    // Its recording has passed already (a wall-time log whose services
    // answered sooner than the replay's clock reaches): pair and pass on.
    if (auto rec = state.unanswered.find(key); rec != state.unanswered.end()) {
      pair(state, rec->second, bytes);
      state.unanswered.erase(rec);
      pass_on(state, bytes);
      return;
    }
    state.held.push_back(HeldMessage{key, std::move(bytes), clock_.now()});
  }

  void on_recorded_output(ChannelState& state, Bytes recorded) {
    const Utime key =
        state.pairing == PairingKey::kSequence ? state.comparison.recorded : utime_of(recorded);
    ++state.comparison.recorded;
    while (!state.held.empty() && state.held.front().key < key) release_front(state, false);
    if (!state.held.empty() && state.held.front().key == key) {
      pair(state, recorded, state.held.front().bytes);
      release_front(state, true);
      return;
    }
    if (auto it = state.unpaired.find(key); it != state.unpaired.end()) {
      pair(state, recorded, it->second);
      state.unpaired.erase(it);
      return;
    }
    state.unanswered.emplace(key, std::move(recorded));
  }

  void release_overdue() {
    for (auto& [channel, state] : channels_) {
      while (!state.held.empty() && state.held.front().produced + hold_ < clock_.now())
        release_front(state, false);
    }
  }

  void release_front(ChannelState& state, bool paired) {
    HeldMessage message = std::move(state.held.front());
    state.held.pop_front();
    pass_on(state, message.bytes);
    if (!paired) state.unpaired.emplace(message.key, std::move(message.bytes));
  }

  // Delivers a replayed output to the other replayed services that consume
  // it and into the replayed log.
  void pass_on(const ChannelState& state, const Bytes& bytes) {
    const std::string& channel = state.comparison.channel;
    write(channel, bytes.data(), static_cast<int32_t>(bytes.size()), clock_.now());
    for (size_t i = 0; i < services_.size(); ++i) {
      if (i == state.producer || !services_[i].inputs.count(channel)) continue;
      deliver(services_[i], channel, bytes.data(), static_cast<unsigned>(bytes.size()));
    }
  }

  void pair(ChannelState& state, const Bytes& recorded, const Bytes& replayed) {
    ChannelComparison& c = state.comparison;
    if (comparable(c.channel, recorded) == comparable(c.channel, replayed)) {
      ++c.identical;
      return;
    }
    const MessageDifference d = message_difference(c.channel, recorded, replayed);
    c.largest_difference = std::max(c.largest_difference, d.value);
    c.largest_stamp_difference = std::max(c.largest_stamp_difference, d.stamp);
    if (d.value <= options_.tolerance && d.stamp <= options_.stamp_tolerance) ++c.within_tolerance;
  }

  void write(const std::string& channel, const void* data, int32_t size, Utime timestamp) {
    if (!replayed_log_) return;
    lcm::LogEvent e;
    e.eventnum = 0;
    e.timestamp = timestamp;
    e.channel = channel;
    e.datalen = size;
    e.data = const_cast<void*>(data);
    replayed_log_->writeEvent(&e);
  }

  const ReplayOptions& options_;
  const bool follow_sim_clock_;
  Utime hold_ = 0;
  SimFollowClock clock_;
  // Declared before the services, so that their nodes unsubscribe from a
  // live LCM when the session ends.
  std::vector<ReplayedService> services_;
  std::vector<std::unique_ptr<CaptureContext>> captures_;
  std::optional<sensing::SensorInterfaceService> sensor_;
  std::optional<mapping::MapperService> mapper_;
  std::optional<planning::GlobalPlannerService> planner_;
  std::optional<rh::RhOptimizerService> optimizer_;
  std::map<std::string, ChannelState> channels_;
  std::set<std::string> replayed_heartbeats_;
  std::unique_ptr<lcm::LogFile> replayed_log_;
  ReplayResult result_;
  Utime first_time_ = INT64_MIN;
  Utime last_time_ = INT64_MIN;
};

struct LogSurvey {
  int64_t events = 0;
  Utime first_timestamp = 0;
  std::set<std::string> channels;
};

std::unique_ptr<lcm::LogFile> open_log(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw ReplayInputError("log file '" + path + "' not found");
  if (!std::filesystem::is_regular_file(path, ec))
    throw ReplayInputError("'" + path + "' is not a regular file");
  auto log = std::make_unique<lcm::LogFile>(path, "r");
  if (!log->good()) throw ReplayInputError("cannot open log file '" + path + "'");
  return log;
}

LogSurvey survey(const std::string& path) {
  auto log = open_log(path);
  LogSurvey s;
  while (const lcm::LogEvent* e = log->readNextEvent()) {
    if (s.events++ == 0) s.first_timestamp = e->timestamp;
    s.channels.insert(e->channel);
  }
  if (s.events == 0)
    throw ReplayInputError("'" + path + "' holds no LCM events (not an LCM log, or empty)");
  return s;
}

// An input without which a service would publish nothing worth comparing.
void check_inputs(const LogSurvey& survey, const std::vector<std::string>& services,
                  const std::string& path) {
  std::set<std::string> produced;
  for (const auto& name : services)
    for (const auto& channel : spec_of(name).outputs) produced.insert(channel);
  auto require = [&](const std::string& service, const std::string& channel) {
    if (produced.count(channel) || survey.channels.count(channel)) return;
    throw ReplayInputError("'" + path + "' has no " + channel + " messages, which " + service +
                           " needs" +
                           (channel == channels::kScanWorld || channel == channels::kCuboids ||
                                    channel == channels::kObstacleGrid
                                ? " (or replay the service that makes them too)"
                                : ""));
  };
  for (const auto& name : services) {
    require(name, channels::kNavState);
    if (name == "sensor_interface") require(name, channels::kLidarRaw);
    if (name == "mapper") require(name, channels::kScanWorld);
    if (name == "global_planner") {
      require(name, channels::kMission);
      require(name, channels::kCuboids);
    }
    if (name == "rh_optimizer") {
      require(name, channels::kMission);
      require(name, channels::kObstacleGrid);
    }
  }
}

YamlReader config_in(const std::string& dir, const std::string& file) {
  const std::filesystem::path path = std::filesystem::path(dir) / file;
  if (!dir.empty() && std::filesystem::exists(path)) return YamlReader::load_file(path.string());
  return YamlReader::empty("(defaults)");
}

}  // namespace

const std::vector<std::string>& replayable_services() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& spec : service_specs()) n.push_back(spec.name);
    return n;
  }();
  return names;
}

std::vector<std::string> parse_service_list(const std::string& comma_separated) {
  std::set<std::string> chosen;
  std::stringstream in(comma_separated);
  std::string name;
  const auto& known = replayable_services();
  while (std::getline(in, name, ',')) {
    if (name.empty()) continue;
    if (std::find(known.begin(), known.end(), name) == known.end()) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      throw ReplayInputError("unknown service '" + name + "' (replayable: " + list + ")");
    }
    if (!chosen.insert(name).second) throw ReplayInputError("service '" + name + "' named twice");
  }
  if (chosen.empty()) throw ReplayInputError("no service to replay");
  std::vector<std::string> ordered;
  for (const auto& k : known)
    if (chosen.count(k)) ordered.push_back(k);
  return ordered;
}

ReplayServiceConfigs load_replay_configs(const std::string& config_dir) {
  if (!config_dir.empty() && !std::filesystem::is_directory(config_dir))
    throw ReplayInputError("config folder '" + config_dir + "' not found");
  ReplayServiceConfigs c;
  auto sensor_reader = config_in(config_dir, "sensor_interface.yaml");
  auto mapper_reader = config_in(config_dir, "mapper.yaml");
  auto planner_reader = config_in(config_dir, "global_planner.yaml");
  auto optimizer_reader = config_in(config_dir, "rh_optimizer.yaml");
  c.sensor_interface = sensing::load_sensor_interface_config(sensor_reader);
  c.mapper = mapping::load_mapper_config(mapper_reader);
  c.global_planner = planning::load_global_planner_config(planner_reader);
  c.rh_optimizer = rh::load_rh_optimizer_config(optimizer_reader);
  // As ofn_sim_runner: replay time does not pass during a solve, and a wall
  // cap would make the result depend on the machine's load.
  c.rh_optimizer.optimizer.max_solve_time = 10.0;
  return c;
}

bool ReplayResult::matches() const {
  return std::all_of(channels.begin(), channels.end(),
                     [](const ChannelComparison& c) { return c.matches(); });
}

ReplayResult replay_log(const std::string& log_path, const ReplayOptions& options) {
  if (options.services.empty()) throw ReplayInputError("no service to replay");
  for (const auto& name : options.services) spec_of(name);
  if (!(options.tolerance >= 0) || !(options.stamp_tolerance >= 0))
    throw ReplayInputError("tolerances must be >= 0");
  const LogSurvey s = survey(log_path);
  check_inputs(s, options.services, log_path);

  // Lockstep logs are stamped with simulation time (from 0); a log whose
  // stamps are wall time and which carries SIM_CLOCK comes from services
  // that followed SIM_CLOCK.
  constexpr Utime kWallEpochSince2001 = 978307200LL * kMicrosPerSecond;
  bool follow_sim_clock = false;
  switch (options.clock) {
    case ReplayClockSource::kAuto:
      follow_sim_clock =
          s.first_timestamp >= kWallEpochSince2001 && s.channels.count(channels::kSimClock) > 0;
      break;
    case ReplayClockSource::kLogTime:
      break;
    case ReplayClockSource::kSimClock:
      if (!s.channels.count(channels::kSimClock))
        throw ReplayInputError("'" + log_path + "' has no SIM_CLOCK messages to follow");
      follow_sim_clock = true;
      break;
  }

  Session session(options, follow_sim_clock);
  if (!options.replayed_log_path.empty()) session.open_replayed_log(options.replayed_log_path);
  auto log = open_log(log_path);
  while (const lcm::LogEvent* e = log->readNextEvent()) session.on_event(*e);
  return session.finish();
}

std::string format_comparison(const ReplayResult& result) {
  std::ostringstream out;
  char line[320];
  std::snprintf(line, sizeof line, "%-14s %9s %9s %9s %10s %8s %6s  %-12s %s\n", "channel",
                "recorded", "replayed", "identical", "within-tol", "missing", "extra",
                "largest diff", "largest stamp diff (s)");
  out << line;
  for (const auto& c : result.channels) {
    const int64_t differing = c.recorded - c.missing - c.identical;
    std::string largest = "-", stamp = "-";
    if (differing > 0 && std::isinf(c.largest_difference)) {
      largest = "structure";
    } else if (differing > 0) {
      char v[64];
      std::snprintf(v, sizeof v, "%.3g", c.largest_difference);
      largest = v;
    }
    if (differing > 0) {
      char v[64];
      std::snprintf(v, sizeof v, "%.3g", c.largest_stamp_difference);
      stamp = v;
    }
    std::snprintf(line, sizeof line, "%-14s %9lld %9lld %9lld %10lld %8lld %6lld  %-12s %s%s\n",
                  c.channel.c_str(), static_cast<long long>(c.recorded),
                  static_cast<long long>(c.replayed), static_cast<long long>(c.identical),
                  static_cast<long long>(c.within_tolerance), static_cast<long long>(c.missing),
                  static_cast<long long>(c.extra), largest.c_str(), stamp.c_str(),
                  c.matches() ? "" : "  DIFFERS");
    out << line;
  }
  std::snprintf(line, sizeof line,
                "%.1f s of log, %lld events, %lld inputs fed, clock from %s, tolerance %g "
                "(stamps %g s)\n",
                result.duration, static_cast<long long>(result.events_read),
                static_cast<long long>(result.inputs_fed), result.clock.c_str(), result.tolerance,
                result.stamp_tolerance);
  out << line;
  out << "structure: a pair differs in sizes, status, mode, ids or text\n";
  for (const auto& [service, rejected] : result.rejected_inputs)
    if (rejected > 0) out << service << " rejected " << rejected << " inputs (see its log lines)\n";
  out << (result.matches() ? "replay reproduces the recording\n"
                           : "replay DIFFERS from the recording\n");
  return out.str();
}

}  // namespace ofn::sim
