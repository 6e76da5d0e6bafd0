#include "ofn/common/channel_table.hpp"

#include "ofn/common/channels.hpp"

namespace ofn {
namespace {

constexpr size_t kKiB = 1024;

}  // namespace

bool ChannelInfo::matches(const std::string& channel) const {
  return prefix ? channel.rfind(name, 0) == 0 && channel.size() > std::string(name).size()
                : channel == name;
}

// The cap of every channel, with the largest message of the channel in
// six lockstep flights with the shipped configs (bench3, tree,
// trap_courtyard, trap_wide_wall, bench/random_field.py's dense field 43
// and out-and-back trap field 7; 2026-12-01) and, for REF_TRAJ, bench3 with
// samples every 0.01 s (sample_period, the finest it allows). Each cap
// leaves room for the settings that make the message larger; one that
// makes it larger still (a finer grid, a denser scan) raises the cap here,
// and until it does the receivers count and log the messages "oversized".
// clang-format off
const std::vector<ChannelInfo>& channel_table() {
  static const std::vector<ChannelInfo> table = {
      // fixed size, 28 to 178 B (the frame "NED")
      {channels::kNavState,         "nav_state_t",         kKiB},
      {channels::kActuatorCmd,      "actuator_cmd_t",      kKiB},
      {channels::kSimClock,         "sim_clock_t",         kKiB},
      // largest 208 B: 32 B a waypoint; 2,000
      {channels::kMission,          "mission_t",           64 * kKiB},
      // largest 835 B: 73 B an obstacle; 890
      {channels::kVirtualObstacles, "virtual_obstacles_t", 64 * kKiB},
      // largest 23,220 B: 17 B a beam, 1,364 beams; the cap holds 7,700
      {channels::kLidarRaw,         "lidar_scan_t",        128 * kKiB},
      // largest 16,384 B: 12 B a point or free-ray end, one a beam
      {channels::kScanWorld,        "scan_world_t",        128 * kKiB},
      {channels::kScannerStatus,    "scanner_status_t",    kKiB},
      // largest 55,764 B: 4 B a cell; the whole 141 x 141 window is 80 KB,
      // at 0.5 m resolution 318 KB
      {channels::kObstacleGrid,     "obstacle_grid_t",     512 * kKiB},
      // largest 1,270 B: 69 B a cuboid; the cap holds 950
      {channels::kCuboids,          "cuboid_list_t",       64 * kKiB},
      // largest 4,021 B: 24 B a point; 2,700
      {channels::kGlobalPath,       "global_path_t",       64 * kKiB},
      // largest 32 B (none found): 40 B a passage; 1,600
      {channels::kNarrowPassages,   "narrow_passages_t",   64 * kKiB},
      // largest 449 B, the spline alone; 203 KB with samples every 0.01 s
      {channels::kRefTraj,          "ref_traj_t",          1024 * kKiB},
      // largest 423 B: fixed fields and a one-line message
      {channels::kSolverStats,      "solver_stats_t",      4 * kKiB},
      {channels::kControlStatus,    "control_status_t",    kKiB},
      // HEARTBEAT_<NAME>: largest 884 B, the flight monitor's (fixed fields, three
      // short strings and twelve inputs of 45 B and a channel name each)
      {channels::kHeartbeatPrefix,  "heartbeat_t",         4 * kKiB, true},
  };
  return table;
}
// clang-format on

const ChannelInfo* find_channel(const std::string& channel) {
  for (const auto& entry : channel_table())
    if (entry.matches(channel)) return &entry;
  return nullptr;
}

}  // namespace ofn
