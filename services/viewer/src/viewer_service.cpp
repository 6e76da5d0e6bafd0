#include "ofn/viewer/viewer_service.hpp"

#include "ofn/common/channels.hpp"
#include "ofn/common/validate/control_status.hpp"
#include "ofn/common/validate/cuboid_list.hpp"
#include "ofn/common/validate/global_path.hpp"
#include "ofn/common/validate/mission.hpp"
#include "ofn/common/validate/narrow_passages.hpp"
#include "ofn/common/validate/nav_state.hpp"
#include "ofn/common/validate/obstacle_grid.hpp"
#include "ofn/common/validate/ref_traj.hpp"
#include "ofn/common/validate/solver_stats.hpp"
#include "ofn/common/validate/virtual_obstacles.hpp"

namespace ofn::viewer {

ViewerService::ViewerService(lcm::LCM& lcm, const Clock& clock, ViewStateConfig config,
                             SnapshotHub& hub, double snapshot_rate)
    : node_("viewer", lcm, clock), view_(std::move(config)), hub_(hub) {
  if (!(snapshot_rate > 0)) throw std::invalid_argument("snapshot rate must be > 0");
  // The node's own time checks are off: the viewer watches flights on any
  // timeline (a replayed log, a simulation, the field) and the view state
  // orders the stamps per channel itself.
  const SubscribeOptions any_time{0.0, 0.0};
  node_.subscribe<nav_state_t>(
      channels::kNavState,
      [this](const nav_state_t& m) { take(channels::kNavState, view_.on_nav_state(m)); }, any_time);
  node_.subscribe<control_status_t>(
      channels::kControlStatus,
      [this](const control_status_t& m) {
        take(channels::kControlStatus, view_.on_control_status(m));
      },
      any_time);
  node_.subscribe<ref_traj_t>(
      channels::kRefTraj,
      [this](const ref_traj_t& m) { take(channels::kRefTraj, view_.on_ref_traj(m)); }, any_time);
  node_.subscribe<solver_stats_t>(
      channels::kSolverStats,
      [this](const solver_stats_t& m) { take(channels::kSolverStats, view_.on_solver_stats(m)); },
      any_time);
  node_.subscribe<global_path_t>(
      channels::kGlobalPath,
      [this](const global_path_t& m) { take(channels::kGlobalPath, view_.on_global_path(m)); },
      any_time);
  node_.subscribe<narrow_passages_t>(
      channels::kNarrowPassages,
      [this](const narrow_passages_t& m) {
        take(channels::kNarrowPassages, view_.on_narrow_passages(m));
      },
      any_time);
  node_.subscribe<cuboid_list_t>(
      channels::kCuboids,
      [this](const cuboid_list_t& m) { take(channels::kCuboids, view_.on_cuboids(m)); }, any_time);
  node_.subscribe<obstacle_grid_t>(
      channels::kObstacleGrid,
      [this](const obstacle_grid_t& m) {
        take(channels::kObstacleGrid, view_.on_obstacle_grid(m));
      },
      any_time);
  node_.subscribe<mission_t>(
      channels::kMission,
      [this](const mission_t& m) { take(channels::kMission, view_.on_mission(m)); }, any_time);
  node_.subscribe<virtual_obstacles_t>(
      channels::kVirtualObstacles,
      [this](const virtual_obstacles_t& m) {
        take(channels::kVirtualObstacles, view_.on_virtual_obstacles(m));
      },
      any_time);
  node_.add_timer(
      1.0 / snapshot_rate, [this] { publish_snapshot(); }, "snapshot");
  node_.set_state("running");
}

void ViewerService::take(const std::string& channel, const std::string& rejection) {
  // The view state counted it; the node counts and logs it (rate limited)
  // and reports it in the heartbeat like any service's rejection.
  if (!rejection.empty()) node_.reject(channel, rejection);
}

void ViewerService::publish_snapshot() {
  // The node counts every rejection: those it made before the view state
  // saw the message (undecodable, failed validate()) and the view's own,
  // which take() passes on; the view's are also in "counters".
  auto snapshot = view_.snapshot();
  const auto& c = node_.counters();
  snapshot["bus"] = {{"received", c.received}, {"rejected", c.rejected}};
  hub_.publish(ViewState::to_text(snapshot));
}

}  // namespace ofn::viewer
