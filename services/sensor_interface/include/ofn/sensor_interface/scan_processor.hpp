#pragma once
// Turns one raw LIDAR scan into validated world-frame points: rejects beams
// the sensor flagged (no return, saturated), impossible ranges and isolated
// spikes, turns max-range beams into free rays, and places every beam with
// the vehicle pose of its own firing time.
//
// Saturated beams are rejected whatever range they carry: a saturated
// receiver holds the last range it measured, which paints the space above a
// wall's top as more wall (the first bench3 flight of the paper).

#include <cstdint>
#include <optional>
#include <vector>

#include "ofn/common/time.hpp"
#include "ofn/common/frames.hpp"
#include "ofn/common/lidar_geometry.hpp"
#include "ofn/sensor_interface/pose_buffer.hpp"

namespace ofn::sensing {

/// Beam status as the sensor reports it (lidar_scan_t's constants).
enum class BeamStatus : int8_t { kOk = 0, kNoReturn = 1, kSaturated = 2, kMaxRange = 3 };

struct RawBeam {
  int32_t dt_us = 0;       // firing time after the scan's utime
  double elevation = 0;    // rad, in the scan plane, positive up
  double layer_angle = 0;  // rad, out of the scan plane, towards +y
  double range = 0;        // m
  BeamStatus status = BeamStatus::kOk;
};

struct RawScan {
  Utime utime = 0;  // first beam
  int32_t scan_index = 0;
  double max_range = 0;  // m
  std::vector<RawBeam> beams;
};

struct ScanProcessorConfig {
  double min_range = 0.5;             // m; closer returns are the airframe or noise
  double max_range_fraction = 0.995;  // OK returns at or beyond this fraction count as max range
  double spike_distance = 1.0;        // m
  double spike_range_factor = 0.02;   // neighbour tolerance grows with range
  int free_ray_stride = 2;            // every n-th max-range beam becomes a free ray
  LidarMount mount;
};

/// What happened to the beams of one scan.
struct ScanCounters {
  int no_return = 0;
  int saturated = 0;
  int invalid_range = 0;  // NaN, negative or below min_range
  int max_range = 0;      // free space, not a point (some become free rays)
  int spikes = 0;         // isolated returns removed
  /// Beams dropped as unusable: every one that is neither a point nor free space.
  int rejected() const { return no_return + saturated + invalid_range + spikes; }
};

struct WorldScan {
  Utime utime = 0;
  int32_t scan_index = 0;
  Vec3 sensor_origin = Vec3::Zero();  // world NED, at the scan's mid time
  std::vector<Vec3> points;           // world NED
  std::vector<Vec3> free_ray_ends;    // world NED, at max_range along the beam
  ScanCounters counters;
};

enum class ScanStatus { kOk, kNoPose, kOutOfOrder };

struct ScanResult {
  ScanStatus status = ScanStatus::kOk;
  WorldScan scan;  // filled only for kOk
};

class ScanProcessor {
 public:
  /// Throws std::invalid_argument naming the first out-of-range setting.
  explicit ScanProcessor(ScanProcessorConfig config = {});

  /// kOutOfOrder when the scan is not newer than the last processed one;
  /// kNoPose when any beam's time has no pose in `poses` (the whole scan is
  /// dropped then). Only a kOk scan becomes the last processed one.
  ScanResult process(const RawScan& scan, const PoseBuffer& poses);

  const ScanProcessorConfig& config() const { return config_; }
  std::optional<Utime> last_scan_utime() const { return last_scan_utime_; }

 private:
  enum class BeamClass : int8_t { kCandidate, kRejected, kMaxRange };

  void classify(const RawScan& scan, ScanCounters& counters);
  void remove_spikes(const RawScan& scan, ScanCounters& counters);
  bool supported(const RawScan& scan, size_t beam, size_t neighbour) const;

  ScanProcessorConfig config_;
  std::optional<Utime> last_scan_utime_;
  // Per-scan scratch, kept to avoid allocating on every scan.
  std::vector<BeamClass> classes_;
  std::vector<uint32_t> order_;       // beams sorted by layer, then elevation
  std::vector<size_t> layer_starts_;  // into order_, plus one past the end
  std::vector<uint8_t> isolated_;
};

}  // namespace ofn::sensing
