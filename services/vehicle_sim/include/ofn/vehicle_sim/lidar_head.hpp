#pragma once
// The simulated LIDAR head: a vertically scanning multi-layer 2-D laser of
// the Sick LD-MRS kind on the vehicle. Every beam is cast into the world with
// the vehicle's pose at the beam's own time, so a scan taken while the
// vehicle moves and yaws is distorted as a real one is. No LCM in here.

#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <random>
#include <utility>
#include <vector>

#include "ofn/common/time.hpp"
#include "ofn/common/frames.hpp"
#include "ofn/common/lidar_geometry.hpp"
#include "ofn/world/world.hpp"

namespace ofn::vehicle {

/// Beam status, numerically equal to lidar_scan_t's constants.
enum LidarStatus : int8_t {
  kLidarOk = 0,         // range valid
  kLidarNoReturn = 1,   // dropout: no usable echo
  kLidarSaturated = 2,  // range is garbage
  kLidarMaxRange = 3,   // nothing within max_range; range = max_range
};

struct LidarConfig {
  bool enabled = true;
  double scan_rate = 12.5;                    // Hz, scans per second
  int layers = 4;                             // beams per elevation step, fanned out of the plane
  double layer_spacing = deg2rad(0.8);        // rad; layer angles symmetric about 0
  double elevation_min = deg2rad(-42.5);      // rad, first beam of a scan
  double elevation_max = deg2rad(42.5);       // rad, last beam of a scan
  double angular_resolution = deg2rad(0.25);  // rad between elevation steps
  double max_range = 0;                       // m; 0: the scenario's sensor range
  double min_range = 0.5;                     // m; closer echoes are not measured
  double range_noise_sigma = 0.03;            // m, Gaussian
  double dropout_probability = 0.01;          // valid return reported NO_RETURN
  double outlier_probability = 0.0;           // beam reported OK at a uniform random range
  double saturation_range = 1.0;              // m; closer returns are SATURATED
  double saturation_probability = 0.0;        // no-return beam reported SATURATED, range held
  uint32_t seed = 1;
  Vec3 mount_offset = Vec3::Zero();  // m, sensor origin in the body frame
  Vec3 mount_rpy = Vec3::Zero();     // rad, sensor attitude in the body frame

  LidarMount mount() const;
};

/// Range used when neither the config nor the scenario gives one (m).
constexpr double kDefaultLidarMaxRange = 61.0;

struct LidarBeam {
  int32_t dt_us = 0;      // from the scan start
  float elevation = 0;    // rad
  float layer_angle = 0;  // rad
  float range = 0;        // m
  int8_t status = kLidarOk;
  int truth_id = -1;  // what the beam really hit: -1 nothing, 0 ground, else obstacle id
};

struct LidarScan {
  Utime utime = 0;  // time of the first beam
  int32_t scan_index = 0;
  double max_range = 0;
  std::vector<LidarBeam> beams;
};

/// Body pose (world NED position, world-from-body attitude) at a time.
using PoseAt = std::function<std::pair<Vec3, Quat>(Utime)>;

class LidarHead {
 public:
  /// default_max_range: used when config.max_range is 0 (the scenario's
  /// sensor range); 0 there too means kDefaultLidarMaxRange.
  LidarHead(const LidarConfig& config, double default_max_range);

  /// Casts every beam whose time is <= t and not cast yet. The pose given is
  /// the body's at t; beams between the previous call and t use the pose
  /// interpolated to their own time. Scans start at whole multiples of the
  /// scan period, the first at or after the first call.
  void advance(Utime t, const Vec3& body_position, const Quat& world_from_body,
               const world::World& world);
  /// Oldest scan whose last beam has been cast, if any.
  std::optional<LidarScan> take_completed_scan();

  /// A whole scan starting at t0, each elevation step cast with the pose
  /// pose_at gives for its time (tests, benchmarks). Shares the scan counter
  /// and the random stream with advance().
  LidarScan scan(Utime t0, const PoseAt& pose_at, const world::World& world);

  const LidarConfig& config() const { return config_; }
  double max_range() const { return max_range_; }
  int beams_per_scan() const { return steps_ * config_.layers; }
  int elevation_steps() const { return steps_; }
  Utime period_us() const { return period_us_; }
  /// Time offset of an elevation step from the scan start.
  int32_t step_dt_us(int step) const;

 private:
  void start_scan(Utime t0);
  /// Casts the beams of one elevation step of the current scan.
  void cast_step(int step, const Vec3& body_position, const Quat& world_from_body,
                 const world::World& world);
  double uniform();
  double gaussian();

  LidarConfig config_;
  LidarMount mount_;
  double max_range_;
  int steps_;
  Utime period_us_;
  std::vector<double> layer_angles_;
  std::mt19937 rng_;
  // Range last reported per layer, which a saturated beam repeats.
  std::vector<float> held_range_;

  int32_t next_scan_index_ = 0;
  Utime next_scan_start_ = INT64_MIN;
  std::optional<LidarScan> current_;
  int next_step_ = 0;
  std::deque<LidarScan> completed_;
  Utime last_time_ = INT64_MIN;
  Vec3 last_position_ = Vec3::Zero();
  Quat last_attitude_ = Quat::Identity();
};

}  // namespace ofn::vehicle
