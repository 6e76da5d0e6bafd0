#include "ofn/common/ref_traj_sample.hpp"

#include <algorithm>

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

}  // namespace ofn
