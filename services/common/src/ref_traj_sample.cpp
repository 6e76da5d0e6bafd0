#include "ofn/common/ref_traj_sample.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ofn {

std::optional<RefTrajSample> sample_ref_traj_at(const ref_traj_t& traj, double t) {
  const auto& ts = traj.sample_time;
  if (ts.size() < 2 || t < ts.front() || t > ts.back()) return std::nullopt;
  const size_t i =
      std::min<size_t>(ts.size() - 2, std::upper_bound(ts.begin(), ts.end(), t) - ts.begin() - 1);
  const double f = (t - ts[i]) / (ts[i + 1] - ts[i]);
  auto lerp = [&](const std::vector<std::vector<double>>& v) -> Vec3 {
    const Vec3 a(v[i][0], v[i][1], v[i][2]), b(v[i + 1][0], v[i + 1][1], v[i + 1][2]);
    return (1.0 - f) * a + f * b;
  };
  return RefTrajSample{lerp(traj.position), lerp(traj.velocity), lerp(traj.acceleration)};
}

std::optional<BsplineTrajectory> ref_traj_spline(const ref_traj_t& traj) {
  if (traj.control_points.empty() || traj.knots.empty()) return std::nullopt;
  const double duration = traj.knots.back();
  std::vector<double> normalised(traj.knots.size());
  for (size_t i = 0; i < normalised.size(); ++i) normalised[i] = traj.knots[i] / duration;
  std::vector<Vec3> points;
  points.reserve(traj.control_points.size());
  for (const auto& p : traj.control_points) points.emplace_back(p[0], p[1], p[2]);
  return BsplineTrajectory(traj.degree, std::move(normalised), std::move(points), duration);
}

void set_ref_traj_samples(ref_traj_t& traj, const BsplineTrajectory& spline, double period) {
  if (!(period > 0.0) || !std::isfinite(period))
    throw std::invalid_argument("REF_TRAJ sample period must be > 0");
  traj.sample_time.clear();
  traj.position.clear();
  traj.velocity.clear();
  traj.acceleration.clear();
  const double duration = spline.duration();
  const int n = std::max(2, static_cast<int>(std::ceil(duration / period - 1e-9)) + 1);
  for (int i = 0; i < n; ++i) {
    const double t = std::min(duration, i * period);
    if (!traj.sample_time.empty() && !(t > traj.sample_time.back())) break;
    const Vec3 p = spline.position(t), v = spline.velocity(t), a = spline.acceleration(t);
    traj.sample_time.push_back(t);
    traj.position.push_back({p.x(), p.y(), p.z()});
    traj.velocity.push_back({v.x(), v.y(), v.z()});
    traj.acceleration.push_back({a.x(), a.y(), a.z()});
  }
  traj.num_samples = static_cast<int32_t>(traj.sample_time.size());
}

void expand_ref_traj(ref_traj_t& traj, double period) {
  if (traj.num_samples > 0) return;
  if (const auto spline = ref_traj_spline(traj)) set_ref_traj_samples(traj, *spline, period);
}

}  // namespace ofn
