#include "ofn/tools/arrival_watch.hpp"

#include <cstdio>
#include <cstdlib>

namespace ofn::report {

void ArrivalWatch::set_goal(const Vec3& position, double capture_radius) {
  if (goal_ && (*goal_ - position).norm() < 1e-9 && capture_radius_ == capture_radius) return;
  goal_ = position;
  capture_radius_ = capture_radius;
  done_since_ = INT64_MIN;
}

void ArrivalWatch::on_navigation(Utime stamp, const Vec3& position) {
  if (position_stamp_ != INT64_MIN && stamp < position_stamp_) return;  // reordered
  position_ = position;
  position_stamp_ = stamp;
}

std::optional<std::string> ArrivalWatch::doubt(Utime stamp) const {
  if (!goal_) return "no mission known";
  if (!position_ || std::llabs(stamp - position_stamp_) > to_utime(rules_.max_nav_age))
    return "no navigation at that time";
  const double distance = (*position_ - *goal_).norm();
  if (distance > capture_radius_ + rules_.position_margin) {
    char text[96];
    std::snprintf(text, sizeof text, "vehicle %.1f m from the last waypoint", distance);
    return std::string(text);
  }
  return std::nullopt;
}

void ArrivalWatch::on_status(Utime stamp, bool done) {
  if (arrived_at_) return;
  if (done) {
    if (const auto why = doubt(stamp)) {
      ++unconfirmed_done_;
      last_doubt_ = *why;
      done_since_ = INT64_MIN;
      return;
    }
    if (done_since_ == INT64_MIN || stamp < done_since_) done_since_ = stamp;
    if (stamp - done_since_ >= to_utime(rules_.linger)) arrived_at_ = done_since_;
  } else {
    done_since_ = INT64_MIN;
  }
}

}  // namespace ofn::report
