#include "ofn/common/bspline.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>
#include <utility>

namespace ofn {
namespace {

constexpr int kMaxDegree = 7;
constexpr int kMaxOrder = kMaxDegree + 1;

// Index i of the knot span [knots[i], knots[i+1]) holding s, restricted to
// the spans of the curve so that s = 1 falls into the last one.
int find_span(const std::vector<double>& knots, int degree, int num_control_points, double s) {
  const int last = num_control_points - 1;
  if (s >= knots[static_cast<size_t>(last) + 1]) return last;
  // The last span starting at or before s: with repeated knots this skips
  // the empty spans.
  const auto upper = std::upper_bound(knots.begin() + degree, knots.begin() + last + 1, s);
  return std::max(degree, static_cast<int>(upper - knots.begin()) - 1);
}

// The degree + 1 basis functions that are non-zero in span `span`, or their
// `derivative`-th derivative, at s (Piegl & Tiller, algorithm A2.3). Fixed
// arrays so that trajectory evaluation does not allocate.
void nonzero_basis(const std::vector<double>& knots, int degree, int span, double s, int derivative,
                   std::array<double, kMaxOrder>& out) {
  std::array<std::array<double, kMaxOrder>, kMaxOrder> ndu{};
  std::array<double, kMaxOrder> left{}, right{};
  ndu[0][0] = 1.0;
  for (int j = 1; j <= degree; ++j) {
    left[j] = s - knots[static_cast<size_t>(span + 1 - j)];
    right[j] = knots[static_cast<size_t>(span + j)] - s;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      ndu[j][r] = right[r + 1] + left[j - r];
      const double temp = ndu[r][j - 1] / ndu[j][r];
      ndu[r][j] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    ndu[j][j] = saved;
  }
  out.fill(0.0);
  if (derivative == 0) {
    for (int j = 0; j <= degree; ++j) out[j] = ndu[j][degree];
    return;
  }
  if (derivative > degree) return;
  std::array<std::array<double, kMaxOrder>, 2> a{};
  for (int r = 0; r <= degree; ++r) {
    int s1 = 0, s2 = 1;
    a[0].fill(0.0);
    a[1].fill(0.0);
    a[0][0] = 1.0;
    double value = 0.0;
    for (int k = 1; k <= derivative; ++k) {
      double d = 0.0;
      const int rk = r - k;
      const int pk = degree - k;
      if (r >= k) {
        a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
        d = a[s2][0] * ndu[rk][pk];
      }
      const int j1 = rk >= -1 ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? k - 1 : degree - r;
      for (int j = j1; j <= j2; ++j) {
        a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j];
        d += a[s2][j] * ndu[rk + j][pk];
      }
      if (r <= pk) {
        a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
        d += a[s2][k] * ndu[r][pk];
      }
      value = d;
      std::swap(s1, s2);
    }
    out[r] = value;
  }
  double factor = degree;
  for (int k = 1; k < derivative; ++k) factor *= (degree - k);
  for (int j = 0; j <= degree; ++j) out[j] *= factor;
}

}  // namespace

BsplineBasis::BsplineBasis(int degree, int intervals) : degree_(degree), intervals_(intervals) {
  if (degree < 1 || degree > kMaxDegree)
    throw std::invalid_argument("BsplineBasis: degree must be in [1, 7], got " +
                                std::to_string(degree));
  if (intervals < 1)
    throw std::invalid_argument("BsplineBasis: intervals must be >= 1, got " +
                                std::to_string(intervals));
  knots_.assign(static_cast<size_t>(degree + 1), 0.0);
  for (int i = 1; i < intervals; ++i) knots_.push_back(static_cast<double>(i) / intervals);
  knots_.insert(knots_.end(), static_cast<size_t>(degree + 1), 1.0);
}

Eigen::RowVectorXd BsplineBasis::evaluate(double s, int derivative) const {
  Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(num_control_points());
  if (derivative < 0) throw std::invalid_argument("BsplineBasis: negative derivative");
  s = std::clamp(s, 0.0, 1.0);
  const int span = find_span(knots_, degree_, num_control_points(), s);
  std::array<double, kMaxOrder> values{};
  nonzero_basis(knots_, degree_, span, s, derivative, values);
  for (int j = 0; j <= degree_; ++j) row(span - degree_ + j) = values[j];
  return row;
}

BsplineTrajectory::BsplineTrajectory(int degree, std::vector<double> normalised_knots,
                                     std::vector<Vec3> control_points, double duration)
    : degree_(degree),
      knots_(std::move(normalised_knots)),
      control_points_(std::move(control_points)),
      duration_(duration) {
  if (degree < 1 || degree > kMaxDegree)
    throw std::invalid_argument("BsplineTrajectory: degree must be in [1, 7]");
  if (!(duration > 0.0)) throw std::invalid_argument("BsplineTrajectory: duration must be > 0");
  if (control_points_.size() < static_cast<size_t>(degree + 1) ||
      knots_.size() != control_points_.size() + static_cast<size_t>(degree) + 1)
    throw std::invalid_argument(
        "BsplineTrajectory: need degree + 1 <= control points and knots = control points + "
        "degree + 1");
  for (size_t i = 1; i < knots_.size(); ++i)
    if (knots_[i] < knots_[i - 1])
      throw std::invalid_argument("BsplineTrajectory: knots must not decrease");
}

std::vector<double> BsplineTrajectory::knot_times() const {
  std::vector<double> times(knots_);
  for (double& k : times) k *= duration_;
  return times;
}

Vec3 BsplineTrajectory::evaluate(double t, int derivative) const {
  if (empty() || derivative < 0) return Vec3::Zero();
  if (derivative > degree_) return Vec3::Zero();
  const double s = std::clamp(t / duration_, 0.0, 1.0);
  const int n = static_cast<int>(control_points_.size());
  const int span = find_span(knots_, degree_, n, s);
  std::array<double, kMaxOrder> values{};
  nonzero_basis(knots_, degree_, span, s, derivative, values);
  Vec3 result = Vec3::Zero();
  for (int j = 0; j <= degree_; ++j)
    result += values[j] * control_points_[static_cast<size_t>(span - degree_ + j)];
  double scale = 1.0;
  for (int k = 0; k < derivative; ++k) scale /= duration_;
  return result * scale;
}

}  // namespace ofn
