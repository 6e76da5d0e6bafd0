#pragma once
// When is a live flight over? The ground station ends a run when the
// vehicle has arrived at the last waypoint. A single CONTROL_STATUS saying
// DONE is not proof of that: a stray or forged message would end the run.
// Arrival is taken only when every status for `linger` seconds says DONE and
// the vehicle, by its own navigation, is at the mission's last waypoint all
// that time. Pure logic, no bus: the monitor feeds it what it receives.

#include <cstdint>
#include <optional>
#include <string>

#include "ofn/common/clock.hpp"
#include "ofn/common/frames.hpp"

namespace ofn::report {

struct ArrivalRules {
  /// Seconds of clock time over which every status must say DONE.
  double linger = 1.0;
  /// Distance beyond the last waypoint's capture radius still taken as
  /// "there", m (the controller holds within its position error there).
  double position_margin = 2.0;
  /// A navigation sample older than this does not place the vehicle, s.
  double max_nav_age = 0.5;
};

class ArrivalWatch {
 public:
  explicit ArrivalWatch(ArrivalRules rules = {}) : rules_(rules) {}

  /// The goal of the mission flown (its last waypoint); a new goal restarts
  /// the watch.
  void set_goal(const Vec3& position, double capture_radius);
  void on_navigation(Utime stamp, const Vec3& position);
  /// One CONTROL_STATUS: whether it says DONE.
  void on_status(Utime stamp, bool done);

  /// The time of the first DONE of the run that proved arrival, once it has.
  std::optional<Utime> arrived_at() const { return arrived_at_; }
  /// DONE reports that did not count (no goal, no navigation, away from the goal).
  int64_t unconfirmed_done() const { return unconfirmed_done_; }
  /// Why the last DONE did not count.
  const std::string& last_doubt() const { return last_doubt_; }

 private:
  std::optional<std::string> doubt(Utime stamp) const;

  ArrivalRules rules_;
  std::optional<Vec3> goal_;
  double capture_radius_ = 0.0;
  std::optional<Vec3> position_;
  Utime position_stamp_ = INT64_MIN;
  Utime done_since_ = INT64_MIN;  // first DONE of the current unbroken run
  std::optional<Utime> arrived_at_;
  int64_t unconfirmed_done_ = 0;
  std::string last_doubt_;
};

}  // namespace ofn::report
