#include "ofn/sensor_interface/sensor_interface_service.hpp"

#include <algorithm>
#include <string>

#include "ofn/common/channels.hpp"
#include "ofn/common/validate/lidar_scan.hpp"
#include "ofn/common/validate/nav_state.hpp"

namespace ofn::sensing {
namespace {

// How often waiting scans are checked against pose_wait when no navigation
// arrives to trigger the check.
constexpr double kQueueCheckPeriod = 0.05;  // s

}  // namespace

SensorInterfaceConfig load_sensor_interface_config(YamlReader& r) {
  SensorInterfaceConfig c;
  c.pose_history = r.number_in("pose_history", c.pose_history, 0.1, 60.0);
  c.max_extrapolation = r.number_in("max_extrapolation", c.max_extrapolation, 0.0, 1.0);
  c.pose_wait = r.number_in("pose_wait", c.pose_wait, 0.0, 10.0);
  c.max_queued_scans = r.integer("max_queued_scans", c.max_queued_scans);
  if (c.max_queued_scans < 1 || c.max_queued_scans > 1000)
    r.fail("max_queued_scans", "expected an integer in [1, 1000]");
  c.nav_max_age = r.number_in("nav_max_age", c.nav_max_age, 0.0, 60.0);
  c.scan_max_age = r.number_in("scan_max_age", c.scan_max_age, 0.0, 60.0);

  ScanProcessorConfig& p = c.processor;
  YamlReader filter = r.child("filter");
  p.min_range = filter.number_in("min_range", p.min_range, 0.0, 100.0);
  p.max_range_fraction = filter.number_in("max_range_fraction", p.max_range_fraction, 0.5, 1.0);
  p.spike_distance = filter.number_in("spike_distance", p.spike_distance, 0.0, 100.0);
  p.spike_range_factor = filter.number_in("spike_range_factor", p.spike_range_factor, 0.0, 1.0);
  p.free_ray_stride = filter.integer("free_ray_stride", p.free_ray_stride);
  if (p.free_ray_stride < 1 || p.free_ray_stride > 10000)
    filter.fail("free_ray_stride", "expected an integer in [1, 10000]");
  filter.finish();

  YamlReader mount = r.child("mount");
  const auto offset = mount.numbers("offset", {0.0, 0.0, 0.0});
  for (double v : offset)
    if (std::abs(v) > 10.0) mount.fail("offset", "expected metres within 10 m of the body origin");
  p.mount.offset_body = Vec3(offset[0], offset[1], offset[2]);
  const double roll = mount.number_in("roll_deg", 0.0, -180.0, 180.0);
  const double pitch = mount.number_in("pitch_deg", 0.0, -90.0, 90.0);
  const double yaw = mount.number_in("yaw_deg", 0.0, -180.0, 180.0);
  p.mount.body_from_sensor = quat_from_euler(deg2rad(roll), deg2rad(pitch), deg2rad(yaw));
  mount.finish();
  r.finish();
  return c;
}

RawScan raw_scan_from_message(const lidar_scan_t& msg) {
  RawScan scan;
  scan.utime = msg.utime;
  scan.scan_index = msg.scan_index;
  scan.max_range = msg.max_range;
  const size_t n =
      std::min<size_t>(static_cast<size_t>(std::max(msg.num_beams, 0)), msg.range.size());
  scan.beams.resize(n);
  for (size_t i = 0; i < n; ++i) {
    RawBeam& b = scan.beams[i];
    b.dt_us = msg.beam_dt_us[i];
    b.elevation = msg.elevation[i];
    b.layer_angle = msg.layer_angle[i];
    b.range = msg.range[i];
    b.status = static_cast<BeamStatus>(msg.status[i]);
  }
  return scan;
}

Pose pose_from_message(const nav_state_t& msg) {
  Pose p;
  p.utime = msg.utime;
  p.position = Vec3(msg.position[0], msg.position[1], msg.position[2]);
  p.velocity = Vec3(msg.velocity[0], msg.velocity[1], msg.velocity[2]);
  p.attitude = Quat(msg.quaternion[0], msg.quaternion[1], msg.quaternion[2], msg.quaternion[3]);
  return p;
}

scan_world_t scan_world_message(const WorldScan& scan) {
  auto to_float3 = [](const Vec3& v) {
    return std::vector<float>{static_cast<float>(v.x()), static_cast<float>(v.y()),
                              static_cast<float>(v.z())};
  };
  scan_world_t m;
  m.utime = scan.utime;
  m.scan_index = scan.scan_index;
  m.frame = "NED";
  for (int i = 0; i < 3; ++i) m.sensor_origin[i] = scan.sensor_origin[i];
  m.num_points = static_cast<int32_t>(scan.points.size());
  m.points.reserve(scan.points.size());
  for (const Vec3& p : scan.points) m.points.push_back(to_float3(p));
  m.num_free_rays = static_cast<int32_t>(scan.free_ray_ends.size());
  m.free_ray_ends.reserve(scan.free_ray_ends.size());
  for (const Vec3& p : scan.free_ray_ends) m.free_ray_ends.push_back(to_float3(p));
  m.num_rejected = scan.counters.rejected();
  return m;
}

SensorInterfaceService::SensorInterfaceService(lcm::LCM& lcm, const Clock& clock,
                                               SensorInterfaceConfig config)
    : node_("sensor_interface", lcm, clock),
      config_(std::move(config)),
      poses_(config_.pose_history, config_.max_extrapolation),
      processor_(config_.processor) {
  node_.subscribe<nav_state_t>(
      channels::kNavState, [this](const nav_state_t& m) { on_nav(m); },
      SubscribeOptions{config_.nav_max_age, 0.5});
  node_.subscribe<lidar_scan_t>(
      channels::kLidarRaw, [this](const lidar_scan_t& m) { on_scan(m); },
      SubscribeOptions{config_.scan_max_age, 0.5});
  node_.add_timer(
      kQueueCheckPeriod, [this] { drain_queue(); }, "pose_wait");
}

void SensorInterfaceService::on_nav(const nav_state_t& msg) {
  const auto newest = poses_.newest();
  if (!poses_.insert(pose_from_message(msg))) {
    ++counters_.nav_out_of_order;
    node_.reject(channels::kNavState, "out of order (utime " + std::to_string(msg.utime) +
                                          " not after " + std::to_string(newest->utime) + ")");
    return;
  }
  drain_queue();
}

void SensorInterfaceService::on_scan(const lidar_scan_t& msg) {
  ++counters_.scans_received;
  if (newest_scan_utime_ && msg.utime <= *newest_scan_utime_) {
    ++counters_.dropped_out_of_order;
    node_.reject(channels::kLidarRaw, "scan " + std::to_string(msg.scan_index) +
                                          " out of order (utime " + std::to_string(msg.utime) +
                                          " not after " + std::to_string(*newest_scan_utime_) +
                                          ")");
    return;
  }
  newest_scan_utime_ = msg.utime;
  publish_scanner_status(msg);

  PendingScan pending;
  pending.scan = raw_scan_from_message(msg);
  pending.first_beam = pending.last_beam = msg.utime;
  for (const RawBeam& b : pending.scan.beams) {
    pending.first_beam = std::min(pending.first_beam, msg.utime + b.dt_us);
    pending.last_beam = std::max(pending.last_beam, msg.utime + b.dt_us);
  }
  pending.received = node_.now();
  if (queue_.size() >= static_cast<size_t>(config_.max_queued_scans)) {
    drop_no_pose(queue_.front(), "queue full while waiting for navigation");
    queue_.pop_front();
  }
  queue_.push_back(std::move(pending));
  drain_queue();
}

void SensorInterfaceService::publish_scanner_status(const lidar_scan_t& msg) {
  scanner_status_t status;
  status.utime = msg.utime;
  status.scan_index = msg.scan_index;
  status.beams = static_cast<int32_t>(msg.status.size());
  status.returns =
      static_cast<int32_t>(std::count(msg.status.begin(), msg.status.end(), lidar_scan_t::OK));
  node_.publish(channels::kScannerStatus, status);
}

void SensorInterfaceService::drain_queue() {
  while (!queue_.empty()) {
    const PendingScan& pending = queue_.front();
    const auto oldest = poses_.oldest();
    const auto newest = poses_.newest();
    if (oldest && pending.first_beam < oldest->utime) {
      drop_no_pose(pending, "starts before the oldest buffered pose");
      queue_.pop_front();
      continue;
    }
    if (!newest || newest->utime < pending.last_beam) {
      if (node_.now() - pending.received < to_utime(config_.pose_wait)) return;
      drop_no_pose(pending, "navigation did not cover it within pose_wait");
      queue_.pop_front();
      continue;
    }
    const ScanResult result = processor_.process(pending.scan, poses_);
    switch (result.status) {
      case ScanStatus::kOk:
        publish(result.scan);
        break;
      case ScanStatus::kNoPose:
        drop_no_pose(pending, "a beam has no pose");
        break;
      case ScanStatus::kOutOfOrder:
        ++counters_.dropped_out_of_order;
        node_.reject(channels::kLidarRaw,
                     "scan " + std::to_string(pending.scan.scan_index) + " out of order");
        break;
    }
    queue_.pop_front();
  }
}

void SensorInterfaceService::drop_no_pose(const PendingScan& pending, const std::string& why) {
  ++counters_.dropped_no_pose;
  node_.set_state("degraded");
  // Node::reject counts it in the heartbeat and rate-limits the log line.
  node_.reject(channels::kLidarRaw,
               "scan " + std::to_string(pending.scan.scan_index) + " dropped, no pose: " + why);
}

void SensorInterfaceService::publish(const WorldScan& scan) {
  node_.publish(channels::kScanWorld, scan_world_message(scan));
  ++counters_.scans_published;
  ScanCounters& total = counters_.beams;
  total.no_return += scan.counters.no_return;
  total.saturated += scan.counters.saturated;
  total.invalid_range += scan.counters.invalid_range;
  total.max_range += scan.counters.max_range;
  total.spikes += scan.counters.spikes;
  node_.set_state("running");
}

}  // namespace ofn::sensing
