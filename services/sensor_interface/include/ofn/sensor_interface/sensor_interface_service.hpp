#pragma once
// Onboard1's LIDAR interface: buffers NAV_STATE, holds each LIDAR_RAW scan
// until navigation covers its last beam, filters and transforms it with the
// ScanProcessor and publishes SCAN_WORLD for the mapper.

#include <cstdint>
#include <deque>

#include "ofn/common/config.hpp"
#include "ofn/common/node.hpp"
#include "ofn/lidar_scan_t.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/scan_world_t.hpp"
#include "ofn/scanner_status_t.hpp"
#include "ofn/sensor_interface/pose_buffer.hpp"
#include "ofn/sensor_interface/scan_processor.hpp"

namespace ofn::sensing {

struct SensorInterfaceConfig {
  ScanProcessorConfig processor;
  double pose_history = 2.0;        // s of NAV_STATE kept
  double max_extrapolation = 0.03;  // s a beam may lie past the newest pose
  double pose_wait = 0.3;           // s (clock) a scan waits for navigation to cover it
  int max_queued_scans = 8;         // scans waiting for navigation at once
  double nav_max_age = 0.5;         // s; older NAV_STATE is rejected as stale
  double scan_max_age = 1.0;        // s; older LIDAR_RAW is rejected as stale
};

SensorInterfaceConfig load_sensor_interface_config(YamlReader& reader);

/// lidar_scan_t (already validated) to the core's plain scan.
RawScan raw_scan_from_message(const lidar_scan_t& msg);
/// nav_state_t (already validated) to a pose sample.
Pose pose_from_message(const nav_state_t& msg);
/// The SCAN_WORLD message of a processed scan.
scan_world_t scan_world_message(const WorldScan& scan);

struct SensorInterfaceCounters {
  int64_t scans_received = 0;  // valid LIDAR_RAW handed to the service
  int64_t scans_published = 0;
  int64_t dropped_no_pose = 0;  // waited too long, queue full, or older than the poses
  int64_t dropped_out_of_order = 0;
  int64_t nav_out_of_order = 0;
  ScanCounters beams;  // summed over the published scans
};

class SensorInterfaceService {
 public:
  SensorInterfaceService(lcm::LCM& lcm, const Clock& clock, SensorInterfaceConfig config);
  Node& node() { return node_; }
  const SensorInterfaceCounters& counters() const { return counters_; }
  const PoseBuffer& poses() const { return poses_; }
  size_t queued_scans() const { return queue_.size(); }

 private:
  struct PendingScan {
    RawScan scan;
    Utime first_beam = 0;
    Utime last_beam = 0;
    Utime received = 0;  // clock time
  };

  void on_nav(const nav_state_t& msg);
  void on_scan(const lidar_scan_t& msg);
  // SCANNER_STATUS: the scan was accepted, so the scanner scans (the
  // controller sweeps it only then); published before it waits for poses.
  void publish_scanner_status(const lidar_scan_t& msg);
  /// Processes queued scans in arrival order while navigation covers them;
  /// drops those that can never be covered or have waited too long.
  void drain_queue();
  void drop_no_pose(const PendingScan& pending, const std::string& why);
  void publish(const WorldScan& scan);

  Node node_;
  SensorInterfaceConfig config_;
  PoseBuffer poses_;
  ScanProcessor processor_;
  std::deque<PendingScan> queue_;
  std::optional<Utime> newest_scan_utime_;  // queued or processed
  SensorInterfaceCounters counters_;
};

}  // namespace ofn::sensing
