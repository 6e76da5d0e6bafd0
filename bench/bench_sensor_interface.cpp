// Cost of turning one raw scan into world points: a 4-layer x 340-step scan
// (1360 beams) of a wall with sky above it, vehicle moving and yawing, so
// that every stage runs (classification, spike filter, per-beam pose
// interpolation, free rays).

#include <benchmark/benchmark.h>

#include <cmath>

#include "ofn/sensor_interface/scan_processor.hpp"

namespace {

using ofn::Utime;
using ofn::Vec3;
using ofn::sensing::BeamStatus;
using ofn::sensing::Pose;
using ofn::sensing::PoseBuffer;
using ofn::sensing::RawBeam;
using ofn::sensing::RawScan;
using ofn::sensing::ScanProcessor;

constexpr int kLayers = 4;
constexpr int kSteps = 340;
constexpr Utime kScanStart = 500000;

Pose pose_at(Utime t) {
  Pose p;
  p.utime = t;
  p.velocity = Vec3(8, 1, 0);
  p.position = Vec3(0, 0, -10) + p.velocity * ofn::to_seconds(t);
  p.attitude = ofn::quat_from_euler(0, ofn::deg2rad(-5), 0.5 * ofn::to_seconds(t));
  return p;
}

RawScan wall_scan() {
  RawScan scan;
  scan.utime = kScanStart;
  scan.max_range = 60;
  for (int step = 0; step < kSteps; ++step)
    for (int layer = 0; layer < kLayers; ++layer) {
      RawBeam b;
      b.dt_us = static_cast<int32_t>(scan.beams.size()) * 50;
      b.elevation = ofn::deg2rad(-20.0 + 60.0 * step / (kSteps - 1));
      b.layer_angle = ofn::deg2rad(layer - 1.5);
      // A wall 30 m ahead, 20 m tall; sky above it.
      const double along = 30.0 / (std::cos(b.elevation) * std::cos(b.layer_angle));
      const double height = 10.0 + along * std::sin(b.elevation);
      b.status = height < 20.0 ? BeamStatus::kOk : BeamStatus::kMaxRange;
      b.range = b.status == BeamStatus::kOk ? along : scan.max_range;
      scan.beams.push_back(b);
    }
  return scan;
}

void BM_ScanProcess1360Beams(benchmark::State& state) {
  PoseBuffer poses(30.0, 0.03);
  for (Utime t = 0; t <= 20000000; t += 10000) poses.insert(pose_at(t));
  RawScan scan = wall_scan();
  ScanProcessor processor;
  for (auto _ : state) {
    // Each scan must be newer than the last; the poses cover ~19 s of shifts.
    scan.utime += 1;
    if (scan.utime > 19000000) {
      state.PauseTiming();
      scan.utime = kScanStart;
      processor = ScanProcessor();
      state.ResumeTiming();
    }
    benchmark::DoNotOptimize(processor.process(scan, poses));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(scan.beams.size()));
}
BENCHMARK(BM_ScanProcess1360Beams)->Unit(benchmark::kMicrosecond);

}  // namespace
