#pragma once
// When is a live flight over? The ground station ends a run when the
// vehicle has arrived at the last waypoint. A single CONTROL_STATUS saying
// DONE is not proof of that: a stray or forged message would end the run.
// Arrival is taken only when every status for `linger` seconds says DONE and
// the vehicle, by its own navigation, is at the mission's last waypoint all
// that time. The goal is that of the mission the status names (by id), so a
// stray MISSION on the bus cannot move the goal of the one flown. Pure
// logic, no bus: the monitor feeds it what it receives.

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "ofn/common/frames.hpp"
#include "ofn/common/time.hpp"

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

  /// The goal of mission `mission_id` (its last waypoint).
  void set_goal(int32_t mission_id, const Vec3& position, double capture_radius);
  void on_navigation(Utime stamp, const Vec3& position);
  /// One CONTROL_STATUS: whether it says DONE, and the mission it flies.
  void on_status(Utime stamp, bool done, int32_t mission_id);

  /// The time of the first DONE of the run that proved arrival, once it has.
  std::optional<Utime> arrived_at() const { return arrived_at_; }
  /// DONE reports that did not count (no goal, no navigation, away from the goal).
  int64_t unconfirmed_done() const { return unconfirmed_done_; }
  /// Why the last DONE did not count.
  const std::string& last_doubt() const { return last_doubt_; }

 private:
  struct Goal {
    Vec3 position = Vec3::Zero();
    double capture_radius = 0.0;
  };
  std::optional<std::string> doubt(Utime stamp, int32_t mission_id) const;

  /// Goals by mission id; a few at most (a plan, its replacements).
  static constexpr size_t kMaxGoals = 16;
  ArrivalRules rules_;
  std::map<int32_t, Goal> goals_;
  int32_t done_mission_ = -1;    // the mission of the current run of DONE
  int32_t status_mission_ = -1;  // the mission of the last status
  std::optional<Vec3> position_;
  Utime position_stamp_ = INT64_MIN;
  Utime done_since_ = INT64_MIN;  // first DONE of the current unbroken run
  std::optional<Utime> arrived_at_;
  int64_t unconfirmed_done_ = 0;
  std::string last_doubt_;
};

}  // namespace ofn::report
