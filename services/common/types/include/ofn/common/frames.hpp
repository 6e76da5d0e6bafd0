#pragma once
// Frames and units. Inside the code: SI, world frame local NED (x north,
// y east, z down), body frame x forward / y right / z down. Scenario and
// report files may use the course frame of the benchmarks (x along the
// course, y right, h height above ground) in feet; convert here, at the edge.

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace ofn {

using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;
using Mat3 = Eigen::Matrix3d;

constexpr double kGravity = 9.80665;  // m/s^2
constexpr double kMetresPerFoot = 0.3048;
constexpr double kPi = 3.14159265358979323846;

inline double deg2rad(double d) {
  return d * kPi / 180.0;
}
inline double rad2deg(double r) {
  return r * 180.0 / kPi;
}

/// Wraps an angle to (-pi, pi].
inline double wrap_angle(double a) {
  a = std::fmod(a + kPi, 2.0 * kPi);
  if (a <= 0) a += 2.0 * kPi;
  return a - kPi;
}

/// Body-to-world rotation from roll, pitch, yaw (3-2-1 sequence).
inline Quat quat_from_euler(double roll, double pitch, double yaw) {
  return Quat(Eigen::AngleAxisd(yaw, Vec3::UnitZ()) * Eigen::AngleAxisd(pitch, Vec3::UnitY()) *
              Eigen::AngleAxisd(roll, Vec3::UnitX()));
}

/// Roll, pitch, yaw (3-2-1) of a body-to-world rotation; pitch in [-pi/2, pi/2].
inline Vec3 euler_from_quat(const Quat& q) {
  const Mat3 r = q.normalized().toRotationMatrix();
  const double pitch = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  const double roll = std::atan2(r(2, 1), r(2, 2));
  const double yaw = std::atan2(r(1, 0), r(0, 0));
  return Vec3(roll, pitch, yaw);
}

/// Course frame (x along the course, y right, h up) to NED, both in metres.
/// The benchmarks lay the course along north.
/// A fixed-size array of three numbers (as in LCM messages) as a vector.
inline Vec3 to_vec3(const double (&a)[3]) {
  return Vec3(a[0], a[1], a[2]);
}

/// v scaled down to length `limit` if it is longer; otherwise v.
inline Vec3 clamp_norm(const Vec3& v, double limit) {
  const double n = v.norm();
  return n > limit ? Vec3(v * (limit / n)) : v;
}

/// Distance from p to the segment a-b (to a when the segment is a point).
inline double distance_to_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

inline Vec3 course_to_ned(const Vec3& course) {
  return Vec3(course.x(), course.y(), -course.z());
}
inline Vec3 ned_to_course(const Vec3& ned) {
  return Vec3(ned.x(), ned.y(), -ned.z());
}

/// Guidance frame of a leg (paper Fig. 4): x from the previous to the next
/// waypoint, y to its right, z completing a right-handed set (down for a
/// level leg).
struct GuidanceFrame {
  Vec3 origin;
  Mat3 world_from_guidance;  // columns: guidance axes in world NED

  static GuidanceFrame from_leg(const Vec3& from, const Vec3& to) {
    Vec3 x = to - from;
    if (x.norm() < 1e-9) x = Vec3::UnitX();
    x.normalize();
    // Keep y horizontal so that "up" stays up in the guidance frame.
    Vec3 y = Vec3::UnitZ().cross(x);
    if (y.norm() < 1e-9) y = Vec3::UnitY();
    y.normalize();
    const Vec3 z = x.cross(y);
    GuidanceFrame g;
    g.origin = from;
    g.world_from_guidance.col(0) = x;
    g.world_from_guidance.col(1) = y;
    g.world_from_guidance.col(2) = z;
    return g;
  }
  Vec3 to_guidance(const Vec3& world_point) const {
    return world_from_guidance.transpose() * (world_point - origin);
  }
  Vec3 to_world(const Vec3& guidance_point) const {
    return origin + world_from_guidance * guidance_point;
  }
};

}  // namespace ofn
