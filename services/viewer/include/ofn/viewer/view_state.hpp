#pragma once
// What the live viewer shows, aggregated from the bus: the vehicle and its
// trail, the maps, the routes and plans, the controller's mode and the
// solver's status, rendered as one JSON snapshot for the browser. Pure core:
// decoded messages in, JSON out; no LCM handle, no sockets, no clock (every
// time is a message stamp).
//
// Every input is checked (content by validate(), stamps for order here); a
// rejected message is counted under its reason and leaves the view as it
// was. NAV_STATE is the view's timeline: a navigation stamp that jumps back
// by more than `timeline_reset_gap` is a new flight (a restarted
// simulation, a log played again), and the view starts afresh.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ofn/common/clock.hpp"
#include "ofn/common/frames.hpp"
#include "ofn/control_status_t.hpp"
#include "ofn/cuboid_list_t.hpp"
#include "ofn/global_path_t.hpp"
#include "ofn/mission_t.hpp"
#include "ofn/narrow_passages_t.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/obstacle_grid_t.hpp"
#include "ofn/ref_traj_t.hpp"
#include "ofn/solver_stats_t.hpp"
#include "ofn/virtual_obstacles_t.hpp"
#include "ofn/world/world.hpp"

namespace ofn::viewer {

struct ViewStateConfig {
  /// Trail points kept; the oldest go first.
  size_t trail_max_points = 3000;
  /// m; a navigation sample closer than this to the last trail point only
  /// moves the vehicle, so a hover does not flush the trail.
  double trail_min_spacing = 0.2;
  /// s of navigation time; a layer older than this is marked stale.
  double stale_after = 3.0;
  /// s; a NAV_STATE this far behind the newest one starts a new timeline.
  double timeline_reset_gap = 5.0;
  /// Occupied grid cells sent to the page at most (the nearest to the
  /// vehicle first); the snapshot says how many were left out.
  size_t max_grid_cells = 20000;
  /// The controller flies a plan this long past its stamp before it flies
  /// the plan's stop (controller config ref_traj_timeout).
  double ref_traj_timeout = 0.5;
  /// Deceleration of that stop, as a share of the acceleration limit
  /// (controller config reference_selector.stop_accel_fraction).
  double stop_accel_fraction = 0.8;
  /// Length unit the page shows: "ft" or "m" (the snapshot stays in SI).
  std::string display_unit = "ft";
};

/// Throws std::invalid_argument naming the first bad field.
void check(const ViewStateConfig& config);

/// Rejections by channel and reason, and messages accepted by channel.
struct ViewCounters {
  std::map<std::string, int64_t> accepted;
  std::map<std::string, int64_t> rejected;  // key "CHANNEL: reason"
  int64_t rejected_total = 0;
  int64_t timeline_resets = 0;
  std::string last_rejection;
};

class ViewState {
 public:
  explicit ViewState(ViewStateConfig config = {});

  // Each returns "" when the message was taken into the view, otherwise the
  // reason it was rejected (also counted).
  std::string on_nav_state(const nav_state_t& msg);
  std::string on_control_status(const control_status_t& msg);
  std::string on_ref_traj(const ref_traj_t& msg);
  std::string on_solver_stats(const solver_stats_t& msg);
  std::string on_global_path(const global_path_t& msg);
  std::string on_cuboids(const cuboid_list_t& msg);
  std::string on_obstacle_grid(const obstacle_grid_t& msg);
  std::string on_mission(const mission_t& msg);
  std::string on_virtual_obstacles(const virtual_obstacles_t& msg);
  std::string on_narrow_passages(const narrow_passages_t& msg);

  /// Counts a message the bus layer could not even decode.
  void count_rejection(const std::string& channel, const std::string& reason);

  /// The whole view as JSON (SI units, world NED; see docs/ARCHITECTURE.md).
  nlohmann::json snapshot() const;
  /// `snapshot` as text. Strings from the bus (the scenario name, the
  /// solver's message) need not be UTF-8; bad bytes become U+FFFD rather
  /// than an exception.
  static std::string to_text(const nlohmann::json& snapshot);

  const ViewCounters& counters() const { return counters_; }
  size_t trail_size() const { return trail_.size(); }
  const ViewStateConfig& config() const { return config_; }

 private:
  struct TrailPoint {
    double t;  // s, navigation stamp
    Vec3 position;
  };
  template <class Msg>
  std::string accept(const char* channel, const Msg& msg, Utime stamp, Utime& last_stamp);
  std::string reject(const std::string& channel, const std::string& reason);
  void start_new_timeline();
  std::optional<double> age(Utime stamp) const;  // s behind the newest navigation
  nlohmann::json safe_stop_json() const;

  ViewStateConfig config_;
  ViewCounters counters_;

  std::optional<nav_state_t> nav_;
  std::deque<TrailPoint> trail_;
  double trail_length_ = 0;  // m flown along the trail since the timeline began
  std::optional<control_status_t> status_;
  std::optional<ref_traj_t> ref_traj_;
  std::optional<solver_stats_t> solver_;
  std::optional<global_path_t> path_;
  std::optional<cuboid_list_t> cuboids_;
  std::optional<obstacle_grid_t> grid_;
  std::optional<mission_t> mission_;
  std::optional<virtual_obstacles_t> obstacles_;
  std::optional<narrow_passages_t> passages_;
  world::World truth_;  // the injected obstacles, for the true clearance

  // Newest accepted stamp per channel (INT64_MIN: none yet).
  Utime last_nav_ = INT64_MIN, last_status_ = INT64_MIN, last_ref_ = INT64_MIN,
        last_solver_ = INT64_MIN, last_path_ = INT64_MIN, last_cuboids_ = INT64_MIN,
        last_grid_ = INT64_MIN, last_mission_ = INT64_MIN, last_obstacles_ = INT64_MIN,
        last_passages_ = INT64_MIN;
};

}  // namespace ofn::viewer
