#include "ofn/common/message_caps.hpp"

#include <algorithm>
#include <map>

#include "ofn/bus_auth/trailer.hpp"
#include "ofn/common/channels.hpp"

namespace ofn {
namespace {

constexpr size_t kKiB = 1024;

// The cap of every channel, with the largest message of the channel in
// six lockstep flights with the shipped configs (bench3, tree,
// trap_courtyard, trap_wide_wall, bench/random_field.py's dense field 43
// and out-and-back trap field 7; 2026-12-01) and, for REF_TRAJ, bench3 with
// samples every 0.01 s (sample_period, the finest it allows). Each cap
// leaves room for the settings that make the message larger; one that
// makes it larger still (a finer grid, a denser scan) raises the cap here,
// and until it does the receivers count and log the messages "oversized".
// clang-format off
const std::map<std::string, size_t>& caps() {
  static const std::map<std::string, size_t> table = {
      // largest 23,220 B: 17 B a beam, 1,364 beams; the cap holds 7,700
      {channels::kLidarRaw,         128 * kKiB},
      // largest 16,384 B: 12 B a point or free-ray end, one a beam
      {channels::kScanWorld,        128 * kKiB},
      // largest 55,764 B: 4 B a cell; the whole 141 x 141 window is 80 KB,
      // at 0.5 m resolution 318 KB
      {channels::kObstacleGrid,     512 * kKiB},
      // largest 449 B, the spline alone; 203 KB with samples every 0.01 s
      {channels::kRefTraj,          1024 * kKiB},
      // largest 1,270 B: 69 B a cuboid; the cap holds 950
      {channels::kCuboids,          64 * kKiB},
      // largest 4,021 B: 24 B a point; 2,700
      {channels::kGlobalPath,       64 * kKiB},
      // largest 32 B (none found): 40 B a passage; 1,600
      {channels::kNarrowPassages,   64 * kKiB},
      // largest 208 B: 32 B a waypoint; 2,000
      {channels::kMission,          64 * kKiB},
      // largest 835 B: 73 B an obstacle; 890
      {channels::kVirtualObstacles, 64 * kKiB},
      // largest 423 B: fixed fields and a one-line message
      {channels::kSolverStats,      4 * kKiB},
      // fixed size, 28 to 178 B (the frame "NED")
      {channels::kNavState,         kKiB},
      {channels::kControlStatus,    kKiB},
      {channels::kActuatorCmd,      kKiB},
      {channels::kSimClock,         kKiB},
      {channels::kScannerStatus,    kKiB},
  };
  return table;
}
// clang-format on

// HEARTBEAT_<NAME>: largest 884 B, the flight monitor's (fixed fields, three
// short strings and twelve inputs of 45 B and a channel name each; 149 B
// without the inputs).
constexpr size_t kHeartbeatCap = 4 * kKiB;

}  // namespace

size_t max_message_bytes(const std::string& channel) {
  const auto& table = caps();
  if (const auto found = table.find(channel); found != table.end()) return found->second;
  if (channel.rfind(channels::kHeartbeatPrefix, 0) == 0) return kHeartbeatCap;
  static const size_t largest =
      std::max_element(table.begin(), table.end(), [](const auto& a, const auto& b) {
        return a.second < b.second;
      })->second;
  return largest;
}

size_t max_received_bytes(const std::string& channel) {
  return max_message_bytes(channel) + bus_auth::kMaxTrailerBytes;
}

}  // namespace ofn
