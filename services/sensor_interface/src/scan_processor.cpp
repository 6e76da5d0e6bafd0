#include "ofn/sensor_interface/scan_processor.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace ofn::sensing {
namespace {

// Beams whose layer angles differ by less than this belong to one layer; real
// heads jitter by far less, and their layers lie a degree or so apart.
constexpr double kLayerTolerance = 1e-3;  // rad
// Same-layer neighbours considered on each side of a beam, in elevation steps.
constexpr size_t kLayerNeighbourSteps = 2;

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("scan processor: " + what);
}

}  // namespace

ScanProcessor::ScanProcessor(ScanProcessorConfig config) : config_(std::move(config)) {
  require(config_.min_range >= 0, "min_range must be >= 0");
  require(config_.max_range_fraction > 0 && config_.max_range_fraction <= 1,
          "max_range_fraction must be in (0, 1]");
  require(config_.spike_distance >= 0, "spike_distance must be >= 0");
  require(config_.spike_range_factor >= 0, "spike_range_factor must be >= 0");
  require(config_.free_ray_stride >= 1, "free_ray_stride must be >= 1");
}

void ScanProcessor::classify(const RawScan& scan, ScanCounters& counters) {
  const double max_return = config_.max_range_fraction * scan.max_range;
  classes_.assign(scan.beams.size(), BeamClass::kRejected);
  for (size_t i = 0; i < scan.beams.size(); ++i) {
    const RawBeam& b = scan.beams[i];
    switch (b.status) {
      case BeamStatus::kNoReturn:
        ++counters.no_return;
        break;
      case BeamStatus::kSaturated:
        ++counters.saturated;
        break;
      case BeamStatus::kMaxRange:
        ++counters.max_range;
        classes_[i] = BeamClass::kMaxRange;
        break;
      case BeamStatus::kOk:
        if (!std::isfinite(b.range) || b.range < config_.min_range) {
          ++counters.invalid_range;
        } else if (b.range >= max_return) {
          // The head reports some max-range beams as OK at the range limit.
          ++counters.max_range;
          classes_[i] = BeamClass::kMaxRange;
        } else {
          classes_[i] = BeamClass::kCandidate;
        }
        break;
      default:  // a status this code does not know cannot be trusted as a point
        ++counters.invalid_range;
        break;
    }
  }
}

bool ScanProcessor::supported(const RawScan& scan, size_t beam, size_t neighbour) const {
  if (classes_[neighbour] != BeamClass::kCandidate) return false;
  const double r = scan.beams[beam].range;
  return std::abs(scan.beams[neighbour].range - r) <=
         config_.spike_distance + config_.spike_range_factor * r;
}

void ScanProcessor::remove_spikes(const RawScan& scan, ScanCounters& counters) {
  const auto& beams = scan.beams;
  const size_t n = beams.size();
  // Beam grid: layers by layer angle, each ordered by elevation. Sorting by
  // layer first and then by elevation within each layer keeps the elevation
  // order right even when a layer's angle jitters a little.
  order_.resize(n);
  for (size_t i = 0; i < n; ++i) order_[i] = static_cast<uint32_t>(i);
  std::sort(order_.begin(), order_.end(),
            [&](uint32_t a, uint32_t b) { return beams[a].layer_angle < beams[b].layer_angle; });
  layer_starts_.clear();
  for (size_t k = 0; k < n; ++k)
    if (k == 0 || beams[order_[k]].layer_angle - beams[order_[layer_starts_.back()]].layer_angle >
                      kLayerTolerance)
      layer_starts_.push_back(k);
  layer_starts_.push_back(n);
  const size_t num_layers = layer_starts_.size() - 1;
  for (size_t l = 0; l < num_layers; ++l)
    std::sort(order_.begin() + static_cast<std::ptrdiff_t>(layer_starts_[l]),
              order_.begin() + static_cast<std::ptrdiff_t>(layer_starts_[l + 1]),
              [&](uint32_t a, uint32_t b) { return beams[a].elevation < beams[b].elevation; });

  // The beam of layer `l` nearest in elevation: the same elevation step.
  auto nearest_in_layer = [&](size_t l, double elevation) {
    const auto first = order_.begin() + static_cast<std::ptrdiff_t>(layer_starts_[l]);
    const auto last = order_.begin() + static_cast<std::ptrdiff_t>(layer_starts_[l + 1]);
    auto it = std::lower_bound(first, last, elevation,
                               [&](uint32_t b, double e) { return beams[b].elevation < e; });
    if (it == last ||
        (it != first && elevation - beams[*(it - 1)].elevation < beams[*it].elevation - elevation))
      --it;
    return static_cast<size_t>(*it);
  };

  isolated_.assign(n, 0);
  for (size_t l = 0; l < num_layers; ++l) {
    const size_t begin = layer_starts_[l], end = layer_starts_[l + 1];
    for (size_t k = begin; k < end; ++k) {
      const size_t i = order_[k];
      if (classes_[i] != BeamClass::kCandidate) continue;
      bool has_support = false;
      for (size_t s = 1; s <= kLayerNeighbourSteps && !has_support; ++s) {
        if (k >= begin + s && supported(scan, i, order_[k - s])) has_support = true;
        if (k + s < end && supported(scan, i, order_[k + s])) has_support = true;
      }
      if (!has_support && l > 0)
        has_support = supported(scan, i, nearest_in_layer(l - 1, beams[i].elevation));
      if (!has_support && l + 1 < num_layers)
        has_support = supported(scan, i, nearest_in_layer(l + 1, beams[i].elevation));
      isolated_[i] = !has_support;
    }
  }
  // Decided on the unfiltered scan first, so that removing one spike cannot
  // take the support away from its neighbours.
  for (size_t i = 0; i < n; ++i)
    if (isolated_[i]) {
      classes_[i] = BeamClass::kRejected;
      ++counters.spikes;
    }
}

ScanResult ScanProcessor::process(const RawScan& scan, const PoseBuffer& poses) {
  ScanResult result;
  if (last_scan_utime_ && scan.utime <= *last_scan_utime_) {
    result.status = ScanStatus::kOutOfOrder;
    return result;
  }
  int32_t first_dt = 0, last_dt = 0;
  if (!scan.beams.empty()) {
    const auto [lo, hi] =
        std::minmax_element(scan.beams.begin(), scan.beams.end(),
                            [](const RawBeam& a, const RawBeam& b) { return a.dt_us < b.dt_us; });
    first_dt = lo->dt_us;
    last_dt = hi->dt_us;
  }
  // Poses are contiguous in time: covering the first and the last beam
  // covers every beam in between.
  const Utime first_time = scan.utime + first_dt, last_time = scan.utime + last_dt;
  const auto mid_pose = poses.interpolate(first_time + (last_time - first_time) / 2);
  if (!poses.interpolate(first_time) || !poses.interpolate(last_time) || !mid_pose) {
    result.status = ScanStatus::kNoPose;
    return result;
  }

  WorldScan& out = result.scan;
  out.utime = scan.utime;
  out.scan_index = scan.scan_index;
  out.sensor_origin = config_.mount.origin_world(mid_pose->position, mid_pose->attitude);
  classify(scan, out.counters);
  remove_spikes(scan, out.counters);

  const LidarMount& mount = config_.mount;
  int max_range_seen = 0;
  for (size_t i = 0; i < scan.beams.size(); ++i) {
    const RawBeam& b = scan.beams[i];
    if (classes_[i] == BeamClass::kRejected) continue;
    const bool free_ray = classes_[i] == BeamClass::kMaxRange;
    if (free_ray && max_range_seen++ % config_.free_ray_stride != 0) continue;
    const auto pose = poses.interpolate(scan.utime + b.dt_us);
    if (!pose) {  // unreachable with ordered poses; kept so a gap can never place a beam
      result = ScanResult{ScanStatus::kNoPose, {}};
      return result;
    }
    if (free_ray)
      out.free_ray_ends.push_back(mount.to_world(pose->position, pose->attitude, b.elevation,
                                                 b.layer_angle, scan.max_range));
    else
      out.points.push_back(
          mount.to_world(pose->position, pose->attitude, b.elevation, b.layer_angle, b.range));
  }
  last_scan_utime_ = scan.utime;
  return result;
}

}  // namespace ofn::sensing
