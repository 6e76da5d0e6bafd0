#pragma once
// Every message's content check (ofn/common/message_checks.hpp); a service
// includes only the ones it receives, ofn/common/validate/<message>.hpp.

#include "ofn/common/message_checks.hpp"
#include "ofn/common/validate/actuator_cmd.hpp"
#include "ofn/common/validate/control_status.hpp"
#include "ofn/common/validate/cuboid_list.hpp"
#include "ofn/common/validate/global_path.hpp"
#include "ofn/common/validate/heartbeat.hpp"
#include "ofn/common/validate/lidar_scan.hpp"
#include "ofn/common/validate/mission.hpp"
#include "ofn/common/validate/narrow_passages.hpp"
#include "ofn/common/validate/nav_state.hpp"
#include "ofn/common/validate/obstacle_grid.hpp"
#include "ofn/common/validate/ref_traj.hpp"
#include "ofn/common/validate/scan_world.hpp"
#include "ofn/common/validate/scanner_status.hpp"
#include "ofn/common/validate/sim_clock.hpp"
#include "ofn/common/validate/solver_stats.hpp"
#include "ofn/common/validate/virtual_obstacles.hpp"
