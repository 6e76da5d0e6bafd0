#include "ofn/vehicle_sim/lidar_head.hpp"

#include <algorithm>
#include <cmath>

namespace ofn::vehicle {
namespace {

/// Smallest multiple of `period` at or after t.
Utime ceil_to_multiple(Utime t, Utime period) {
  Utime q = t / period;
  if (q * period < t) ++q;
  return q * period;
}

// A clock jump longer than this many scans skips the scans in between
// instead of casting them all.
constexpr int64_t kMaxCatchUpScans = 4;

}  // namespace

LidarMount LidarConfig::mount() const {
  LidarMount m;
  m.offset_body = mount_offset;
  m.body_from_sensor = quat_from_euler(mount_rpy.x(), mount_rpy.y(), mount_rpy.z());
  return m;
}

LidarHead::LidarHead(const LidarConfig& config, double default_max_range)
    : config_(config),
      mount_(config.mount()),
      max_range_(config.max_range > 0    ? config.max_range
                 : default_max_range > 0 ? default_max_range
                                         : kDefaultLidarMaxRange),
      steps_(
          std::max(1, static_cast<int>(std::lround((config.elevation_max - config.elevation_min) /
                                                   config.angular_resolution)) +
                          1)),
      period_us_(std::max<Utime>(1, to_utime(1.0 / config.scan_rate))),
      rng_(config.seed),
      held_range_(std::max(config.layers, 1), static_cast<float>(max_range_)) {
  config_.layers = std::max(config_.layers, 1);
  for (int k = 0; k < config_.layers; ++k)
    layer_angles_.push_back((k - 0.5 * (config_.layers - 1)) * config_.layer_spacing);
}

int32_t LidarHead::step_dt_us(int step) const {
  return static_cast<int32_t>(static_cast<int64_t>(step) * period_us_ / steps_);
}

double LidarHead::uniform() {
  // From the raw generator output, so that a seed gives the same scans with
  // every standard library.
  return static_cast<double>(rng_()) / 4294967296.0;
}

double LidarHead::gaussian() {
  const double u1 = 1.0 - uniform();  // (0, 1]
  const double u2 = uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
}

void LidarHead::start_scan(Utime t0) {
  LidarScan s;
  s.utime = t0;
  s.scan_index = next_scan_index_++;
  s.max_range = max_range_;
  s.beams.reserve(beams_per_scan());
  current_ = std::move(s);
  next_step_ = 0;
}

void LidarHead::cast_step(int step, const Vec3& body_position, const Quat& world_from_body,
                          const world::World& world) {
  LidarScan& scan = *current_;
  const double elevation =
      steps_ > 1 ? config_.elevation_min +
                       step * (config_.elevation_max - config_.elevation_min) / (steps_ - 1)
                 : config_.elevation_min;
  const Vec3 origin = mount_.origin_world(body_position, world_from_body);
  const Quat world_from_sensor = world_from_body * mount_.body_from_sensor;
  for (int layer = 0; layer < config_.layers; ++layer) {
    const double layer_angle = layer_angles_[layer];
    const Vec3 dir = world_from_sensor * beam_direction_sensor(elevation, layer_angle);
    const auto hit = world.ray_cast(origin, dir, max_range_, -1.0);

    // Every beam draws the same random numbers whatever happens to it, so
    // that changing one fault probability does not reshuffle the others.
    const double noise = config_.range_noise_sigma * gaussian();
    const double dropout_draw = uniform();
    const double outlier_draw = uniform();
    const double outlier_range = config_.min_range + (max_range_ - config_.min_range) * uniform();
    const double saturation_draw = uniform();

    LidarBeam beam;
    beam.dt_us = step_dt_us(step);
    beam.elevation = static_cast<float>(elevation);
    beam.layer_angle = static_cast<float>(layer_angle);
    beam.truth_id = hit ? hit->obstacle_id : -1;
    double range = 0;
    if (hit && hit->range < config_.saturation_range) {
      beam.status = kLidarSaturated;
      range = hit->range;
    } else if (outlier_draw < config_.outlier_probability) {
      beam.status = kLidarOk;
      range = outlier_range;
    } else if (!hit) {
      beam.status = kLidarMaxRange;
      range = max_range_;
    } else if (hit->range < config_.min_range || dropout_draw < config_.dropout_probability) {
      beam.status = kLidarNoReturn;
    } else {
      range = std::max(hit->range + noise, 0.0);
      beam.status = range < max_range_ ? kLidarOk : kLidarMaxRange;
      range = std::min(range, max_range_);
    }
    beam.range = static_cast<float>(range);
    if ((beam.status == kLidarNoReturn || beam.status == kLidarMaxRange) &&
        saturation_draw < config_.saturation_probability) {
      beam.status = kLidarSaturated;
      beam.range = held_range_[layer];
    }
    if (beam.status == kLidarOk || beam.status == kLidarSaturated) held_range_[layer] = beam.range;
    scan.beams.push_back(beam);
  }
}

void LidarHead::advance(Utime t, const Vec3& body_position, const Quat& world_from_body,
                        const world::World& world) {
  if (!config_.enabled) return;
  if (next_scan_start_ == INT64_MIN) next_scan_start_ = ceil_to_multiple(t, period_us_);
  if (!current_ && t - next_scan_start_ > kMaxCatchUpScans * period_us_)
    next_scan_start_ = ceil_to_multiple(t - period_us_, period_us_);
  const bool interpolate = last_time_ != INT64_MIN && last_time_ < t;
  while (true) {
    if (!current_) {
      if (next_scan_start_ > t) break;
      start_scan(next_scan_start_);
    }
    const Utime beam_time = current_->utime + step_dt_us(next_step_);
    if (beam_time > t) break;
    if (interpolate && beam_time < t) {
      const double alpha = std::clamp(
          static_cast<double>(beam_time - last_time_) / static_cast<double>(t - last_time_), 0.0,
          1.0);
      cast_step(next_step_, last_position_ + alpha * (body_position - last_position_),
                last_attitude_.slerp(alpha, world_from_body), world);
    } else {
      cast_step(next_step_, body_position, world_from_body, world);
    }
    if (++next_step_ == steps_) {
      completed_.push_back(std::move(*current_));
      current_.reset();
      next_scan_start_ += period_us_;
    }
  }
  last_time_ = t;
  last_position_ = body_position;
  last_attitude_ = world_from_body;
}

std::optional<LidarScan> LidarHead::take_completed_scan() {
  if (completed_.empty()) return std::nullopt;
  LidarScan s = std::move(completed_.front());
  completed_.pop_front();
  return s;
}

LidarScan LidarHead::scan(Utime t0, const PoseAt& pose_at, const world::World& world) {
  // A scan in progress from advance() is set aside and resumed afterwards.
  std::optional<LidarScan> in_progress = std::move(current_);
  const int in_progress_step = next_step_;
  start_scan(t0);
  for (int step = 0; step < steps_; ++step) {
    const auto [position, attitude] = pose_at(t0 + step_dt_us(step));
    cast_step(step, position, attitude, world);
  }
  LidarScan out = std::move(*current_);
  current_ = std::move(in_progress);
  next_step_ = in_progress_step;
  return out;
}

}  // namespace ofn::vehicle
