#pragma once
// Beam geometry of the vertically scanning LIDAR, shared by the simulated
// head (vehicle_sim) and the sensor interface so that both agree on what a
// (elevation, layer_angle, range) triple means.
//
// Sensor frame: x along the scan's centre beam, y right, z down. The scan
// plane is the sensor's x-z plane (a vertical plane when mounted level):
// elevation rotates the beam up from +x (positive up), layer_angle tilts it
// out of the plane towards +y. The mount places the sensor in the body frame.

#include <cmath>

#include "ofn/common/frames.hpp"

namespace ofn {

/// Unit beam direction in the sensor frame.
inline Vec3 beam_direction_sensor(double elevation, double layer_angle) {
  const double cl = std::cos(layer_angle);
  return Vec3(cl * std::cos(elevation), std::sin(layer_angle), -cl * std::sin(elevation));
}

struct LidarMount {
  Vec3 offset_body = Vec3::Zero();        // m, sensor origin in the body frame
  Quat body_from_sensor = Quat::Identity();

  /// World position of a return, given the body pose at the beam's time.
  Vec3 to_world(const Vec3& body_position, const Quat& world_from_body, double elevation,
                double layer_angle, double range) const {
    const Vec3 in_sensor = beam_direction_sensor(elevation, layer_angle) * range;
    return body_position + world_from_body * (offset_body + body_from_sensor * in_sensor);
  }
  Vec3 origin_world(const Vec3& body_position, const Quat& world_from_body) const {
    return body_position + world_from_body * offset_body;
  }
};

}  // namespace ofn
