#include "ofn/common/message_names.hpp"

#include <cstdio>

#include "ofn/control_status_t.hpp"
#include "ofn/global_path_t.hpp"
#include "ofn/ref_traj_t.hpp"
#include "ofn/solver_stats_t.hpp"

namespace ofn {

const char* control_mode_name(int mode) {
  switch (mode) {
    case control_status_t::HOLD:
      return "HOLD";
    case control_status_t::WAYPOINT:
      return "WAYPOINT";
    case control_status_t::TRAJECTORY:
      return "TRAJECTORY";
    case control_status_t::NAV_STALE:
      return "NAV_STALE";
    case control_status_t::DONE:
      return "DONE";
    case control_status_t::SAFE_STOP:
      return "SAFE_STOP";
    default:
      return "UNKNOWN";
  }
}

const char* ref_traj_mode_name(int mode) {
  switch (mode) {
    case ref_traj_t::NOMINAL:
      return "NOMINAL";
    case ref_traj_t::AVOIDANCE:
      return "AVOIDANCE";
    case ref_traj_t::PREVIOUS:
      return "PREVIOUS";
    case ref_traj_t::BRAKING:
      return "BRAKING";
    case ref_traj_t::LOOK_AROUND:
      return "LOOK_AROUND";
    case ref_traj_t::LOOK_AROUND_LEFT:
      return "LOOK_AROUND_LEFT";
    default:
      return "UNKNOWN";
  }
}

const char* solver_status_name(int status) {
  switch (status) {
    case solver_stats_t::SOLVED:
      return "SOLVED";
    case solver_stats_t::KEPT_PREVIOUS:
      return "KEPT_PREVIOUS";
    case solver_stats_t::BRAKING:
      return "BRAKING";
    case solver_stats_t::NOT_RUN:
      return "NOT_RUN";
    case solver_stats_t::DEFERRED:
      return "DEFERRED";
    case solver_stats_t::LOOKING_AROUND:
      return "LOOKING_AROUND";
    case solver_stats_t::NO_ROUTE:
      return "NO_ROUTE";
    default:
      return "UNKNOWN";
  }
}

const char* path_status_name(int status) {
  switch (status) {
    case global_path_t::OK:
      return "OK";
    case global_path_t::START_INSIDE_OBSTACLE:
      return "START_INSIDE_OBSTACLE";
    case global_path_t::GOAL_INSIDE_OBSTACLE:
      return "GOAL_INSIDE_OBSTACLE";
    case global_path_t::NO_PATH:
      return "NO_PATH";
    case global_path_t::BACKTRACK:
      return "BACKTRACK";
    default:
      return "UNKNOWN";
  }
}

std::string printable(const std::string& text, size_t max_chars) {
  std::string out;
  for (size_t i = 0; i < text.size() && i < max_chars; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c <= 0x7e && c != '\\') {
      out += static_cast<char>(c);
    } else {
      char escaped[5];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", c);
      out += escaped;
    }
  }
  if (text.size() > max_chars) out += "...";
  return out;
}

}  // namespace ofn
