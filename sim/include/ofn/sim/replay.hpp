#pragma once
// Log replay into the mapping and planning services: the recorded inputs of
// the chosen services are fed, in recorded order and at recorded time, into
// fresh instances of the service classes, and what they publish is compared
// with what the recording holds on the same channels.
//
// Each replayed service gets its own memq:// LCM so that its outputs can be
// held back and delivered to the next service of the chain at the point
// where the recording has them, not where the replay happens to produce
// them: a lockstep log then reproduces every handler's input sequence, and
// with it every output, to the bit.

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "ofn/global_planner/global_planner_service.hpp"
#include "ofn/mapper/mapper_service.hpp"
#include "ofn/rh_optimizer/rh_optimizer_service.hpp"
#include "ofn/sensor_interface/sensor_interface_service.hpp"

namespace ofn::sim {

/// A log, a service list or a setting that cannot be replayed (exit code 2).
class ReplayInputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The services a log can be replayed into, in chain (and timer) order:
/// sensor_interface, mapper, global_planner, rh_optimizer.
const std::vector<std::string>& replayable_services();

/// "mapper,rh_optimizer" -> the names in chain order; throws
/// ReplayInputError naming an unknown or repeated service, or an empty list.
std::vector<std::string> parse_service_list(const std::string& comma_separated);

/// Where the replay clock comes from.
enum class ReplayClockSource {
  kAuto,      // log time for simulation-time logs, SIM_CLOCK for wall-time logs that carry it
  kLogTime,   // each event's log timestamp (lockstep runner logs, field logs)
  kSimClock,  // the last SIM_CLOCK message (multi-process simulations recorded by lcm-logger)
};

struct ReplayServiceConfigs {
  sensing::SensorInterfaceConfig sensor_interface;
  mapping::MapperServiceConfig mapper;
  planning::GlobalPlannerServiceConfig global_planner;
  rh::RhOptimizerServiceConfig rh_optimizer;
};

/// The configs in `config_dir` (sensor_interface.yaml, mapper.yaml,
/// global_planner.yaml, rh_optimizer.yaml; a missing file gives defaults),
/// with every optimiser solve bounded by its evaluation count alone, as the
/// lockstep runner does, so that a replay does not depend on the machine's load.
ReplayServiceConfigs load_replay_configs(const std::string& config_dir);

struct ReplayOptions {
  std::vector<std::string> services;  // from parse_service_list
  ReplayServiceConfigs configs;
  ReplayClockSource clock = ReplayClockSource::kAuto;
  /// A message that differs from its recording by at most `tolerance` in
  /// every numeric field (metres, m/s, m/s^2, s of spline time, cost) and by
  /// at most `stamp_tolerance` in its time stamps (utime, t0, last seen)
  /// counts as a match; 0 and 0: bytes must be identical.
  double tolerance = 0.0;
  double stamp_tolerance = 0.0;  // s
  /// Replayed log to write (recorded events with the replayed services'
  /// outputs in place of the recorded ones); empty: none.
  std::string replayed_log_path;
};

/// One compared channel.
struct ChannelComparison {
  std::string channel;
  int64_t recorded = 0;
  int64_t replayed = 0;
  int64_t identical = 0;         // same bytes (SOLVER_STATS: apart from solve_time)
  int64_t within_tolerance = 0;  // not identical, but within ReplayOptions::tolerance
  int64_t missing = 0;           // recorded, never reproduced
  int64_t extra = 0;             // reproduced, not in the recording
  /// Largest field-wise difference over the paired messages, time stamps
  /// aside; infinity when a pair differs in structure (sizes, status, mode,
  /// ids, text).
  double largest_difference = 0.0;
  double largest_stamp_difference = 0.0;  // s

  bool matches() const {
    return missing == 0 && extra == 0 && identical + within_tolerance == recorded &&
           recorded == replayed;
  }
};

struct ReplayResult {
  std::vector<ChannelComparison> channels;  // the replayed services' outputs, in chain order
  std::string clock;                        // which clock drove the replay
  double tolerance = 0.0;                   // as in ReplayOptions
  double stamp_tolerance = 0.0;
  int64_t events_read = 0;
  int64_t inputs_fed = 0;
  double duration = 0.0;  // s of log (clock) time replayed
  /// Inputs the replayed services rejected (validation or staleness), per service.
  std::vector<std::pair<std::string, int64_t>> rejected_inputs;

  bool matches() const;
};

/// Replays `log_path` into the services of `options`. Throws
/// ReplayInputError for a missing or unreadable file, a file with no LCM
/// events, or a log that lacks an input the chosen services cannot work
/// without.
ReplayResult replay_log(const std::string& log_path, const ReplayOptions& options);

/// The per-channel table and a one-line verdict.
std::string format_comparison(const ReplayResult& result);

}  // namespace ofn::sim
