// The mapper keeping up with the scanner: a bench3 approach is scanned once
// (LIDAR head, sensor interface), then the mapper core is timed on those
// scans at 12.5 Hz with its cuboid cycle once a second. The CPU share counter
// is the fraction of one core the mapper needs in real time.

#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "ofn/common/scenario.hpp"
#include "ofn/mapper/mapper.hpp"
#include "ofn/sensor_interface/pose_buffer.hpp"
#include "ofn/sensor_interface/scan_processor.hpp"
#include "ofn/vehicle_sim/lidar_head.hpp"
#include "ofn/world/world.hpp"

namespace {

using namespace ofn;

struct RecordedScans {
  std::vector<mapping::ScanInput> scans;
  std::vector<Vec3> vehicle;
  double scan_rate = 12.5;
};

/// 40 s of level flight at 10 ft/s towards the bench3 wall with the yaw sweep.
const RecordedScans& bench3_scans() {
  static const RecordedScans recorded = [] {
    RecordedScans r;
    const Scenario scenario =
        load_scenario(std::string(OFN_SOURCE_DIR) + "/sim/scenarios/bench3.yaml");
    const world::World world(scenario.obstacles, scenario.ground_altitude);
    vehicle::LidarHead lidar(vehicle::LidarConfig{}, scenario.limits.sensor_range);
    r.scan_rate = lidar.config().scan_rate;
    auto pose_at = [&](Utime t) {
      const double s = to_seconds(t);
      const Vec3 p = scenario.start_position + Vec3(3.048 * s, 0, 0);
      return std::make_pair(p, quat_from_euler(0, 0, deg2rad(20) * std::sin(2 * kPi * 0.2 * s)));
    };
    sensing::PoseBuffer poses(100.0);
    for (Utime t = 0; t <= to_utime(41.0); t += 10000) {
      const auto [p, q] = pose_at(t);
      poses.insert({t, p, Vec3(3.048, 0, 0), q});
    }
    sensing::ScanProcessor processor;
    for (Utime t0 = 0; t0 < to_utime(40.0); t0 += lidar.period_us()) {
      const auto scan = lidar.scan(t0, pose_at, world);
      sensing::RawScan raw{scan.utime, scan.scan_index, scan.max_range, {}};
      for (const auto& b : scan.beams)
        raw.beams.push_back({b.dt_us, b.elevation, b.layer_angle, b.range,
                             static_cast<sensing::BeamStatus>(b.status)});
      const auto out = processor.process(raw, poses);
      if (out.status != sensing::ScanStatus::kOk) continue;
      r.scans.push_back(
          {out.scan.utime, out.scan.sensor_origin, out.scan.points, out.scan.free_ray_ends});
      r.vehicle.push_back(pose_at(t0).first);
    }
    return r;
  }();
  return recorded;
}

void BM_MapperRealTimeBench3(benchmark::State& state) {
  const RecordedScans& recorded = bench3_scans();
  const int per_cycle = static_cast<int>(recorded.scan_rate);
  size_t scans = 0;
  for (auto _ : state) {
    mapping::Mapper mapper{mapping::MapperConfig{}};
    for (size_t i = 0; i < recorded.scans.size(); ++i) {
      mapper.set_vehicle_position(recorded.vehicle[i]);
      mapper.add_scan(recorded.scans[i]);
      benchmark::DoNotOptimize(mapper.grid());
      if (static_cast<int>(i) % per_cycle == per_cycle - 1)
        mapper.update_cuboids(recorded.scans[i].utime);
    }
    scans += recorded.scans.size();
  }
  // Seconds of CPU per second of flight: the share of one core.
  state.counters["cpu_share"] =
      benchmark::Counter(static_cast<double>(scans) / recorded.scan_rate,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["scans"] = static_cast<double>(recorded.scans.size());
}
BENCHMARK(BM_MapperRealTimeBench3)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
