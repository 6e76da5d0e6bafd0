// The mapper's look over tops: a beam of any length, from a sensor
// anywhere, walks only the cells of the grid (a scan point 3.4e38 m away
// held the mapper in one walk for good; found by the bus fuzz).

#include <gtest/gtest.h>

#include <limits>

#include "ofn/mapper/mapper.hpp"

namespace ofn::mapping {
namespace {

MapperConfig grid_only() {
  MapperConfig c;
  c.use_occupancy = false;
  return c;
}

/// The published top of the cell holding (north, east).
float top_at(Mapper& m, double north, double east) {
  const Heightfield& g = m.grid();
  return g.at(g.row_of(north), g.col_of(east));
}

ScanInput scan(Utime t, const Vec3& origin, std::vector<Vec3> hits, std::vector<Vec3> free_ends) {
  ScanInput s;
  s.utime = t;
  s.sensor_origin = origin;
  s.points = std::move(hits);
  s.free_ray_ends = std::move(free_ends);
  return s;
}

TEST(Mapper, ABeamOverATopProvesItHoweverFarItEnds) {
  // A 5 m obstacle 20 m ahead, the sensor 8 m up: a level beam over it
  // proves its top, whether it ends 60 m on, 10^6 m on or at FLT_MAX.
  const Vec3 sensor(0.0, 0.0, -8.0), hit(20.5, 0.5, -5.0);
  for (double far : {60.0, 1.0e6, static_cast<double>(std::numeric_limits<float>::max()), 1e300}) {
    Mapper m(grid_only());
    m.set_vehicle_position(sensor);
    m.add_scan(scan(1, sensor, {hit}, {}));
    const float ceiling = static_cast<float>(m.config().grid.ceiling);
    EXPECT_EQ(top_at(m, hit.x(), hit.y()), ceiling) << "no beam over it yet";
    m.add_scan(scan(2, sensor, {hit}, {Vec3(far, 0.5, -8.0)}));
    EXPECT_LT(top_at(m, hit.x(), hit.y()), 6.0f) << "beam to " << far << " m";
  }
}

TEST(Mapper, ABeamFromOutsideTheGridOnlyCountsWhereItCrossesIt) {
  Mapper m(grid_only());
  m.set_vehicle_position(Vec3(0.0, 0.0, -8.0));
  const Vec3 hit(20.5, 0.5, -5.0);
  m.add_scan(scan(1, Vec3(0.0, 0.0, -8.0), {hit}, {}));
  // From 10^6 m south, level, over the obstacle to 60 m north of it.
  m.add_scan(scan(2, Vec3(-1.0e6, 0.5, -8.0), {}, {Vec3(80.0, 0.5, -8.0)}));
  EXPECT_LT(top_at(m, hit.x(), hit.y()), 6.0f);
  // From FLT_MAX east to FLT_MAX west, past the grid altogether: nothing.
  const double big = std::numeric_limits<float>::max();
  m.add_scan(scan(3, Vec3(0.0, big, -8.0), {Vec3(5.0, -big, -8.0)}, {Vec3(-big, -big, -8.0)}));
  EXPECT_EQ(m.counters().scans, 3);
}

}  // namespace
}  // namespace ofn::mapping
