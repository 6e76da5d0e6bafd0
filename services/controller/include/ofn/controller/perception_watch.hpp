#pragma once
// Whether waypoint guidance may fly on. Guidance flies the leg without a
// map: it is safe only while the planning side confirms, again and again,
// that it has checked the leg against a map fresh from the sensor and
// found it clear (SOLVER_STATS guidance_clear; while it avoids, its plans
// are flown instead, and a plan that does not arrive is no licence to fly
// the blocked leg). The RH
// optimiser's SOLVER_STATS, published at its step rate, says when it
// looked (its stamp) and on which map (map_utime, the stamp of the grid
// built from the latest scan it had). A dead, stopped or cut-off
// optimiser, a mapper that receives no scans (a lossy link drops most of
// the multi-fragment SCAN_WORLD messages), or no status yet: guidance
// stops (the controller flies the stop of braking.hpp and hovers) until
// fresh confirmation returns. Plans already committed by the optimiser are
// not affected: each carries its own stop in space seen free. A clear
// word holds for the leg it was given on (mission and waypoint) only.
// Pure core; times in seconds of the caller's clock.

#include <cmath>
#include <limits>
#include <optional>
#include <string>

namespace ofn::control {

struct PerceptionWatchSettings {
  /// s; the optimiser's last status may be this old (it steps at 10 Hz).
  double max_status_age = 1.0;
  /// s; the map that status was checked on may be this old (the scans
  /// come at 12.5 Hz, the optimiser's field follows at 5 Hz).
  double max_map_age = 1.0;
  /// Off: guidance never waits (a controller flown without a planner).
  bool enabled = true;
};

/// A leg of a mission: the mission's id and the index of the waypoint that
/// ends the leg (-1: none).
struct MissionLeg {
  int mission_id = -1;
  int waypoint = -1;
  bool operator==(const MissionLeg& o) const {
    return mission_id == o.mission_id && waypoint == o.waypoint;
  }
  bool operator!=(const MissionLeg& o) const { return !(*this == o); }
};

class PerceptionWatch {
 public:
  explicit PerceptionWatch(PerceptionWatchSettings settings = {}) : settings_(settings) {}

  /// A planner status stamped `stamp`, checked on a map stamped `map_stamp`
  /// (<= 0: no map yet), saying whether its leg `checked` is clear for
  /// guidance (false while the planner is avoiding, looking around or has no
  /// route: guidance would fly the blocked leg). Older statuses than the
  /// last are ignored.
  void on_status(double stamp, double map_stamp, bool guidance_clear, MissionLeg checked);

  /// Why guidance may not fly leg `flown` on at `now`, or nullopt when it
  /// may.
  std::optional<std::string> stale(double now, MissionLeg flown) const;

  /// Whether a status on a map has ever come: before it, the flight has
  /// not begun (the controller goes on holding rather than stopping).
  bool confirmed_once() const { return confirmed_once_; }

  /// The leg the newest status was given on (none before one).
  const MissionLeg& checked() const { return checked_; }

  const PerceptionWatchSettings& settings() const { return settings_; }

 private:
  PerceptionWatchSettings settings_;
  double status_stamp_ = -std::numeric_limits<double>::infinity();
  double map_stamp_ = -std::numeric_limits<double>::infinity();
  bool confirmed_once_ = false;
  bool guidance_clear_ = false;
  MissionLeg checked_;
};

}  // namespace ofn::control
