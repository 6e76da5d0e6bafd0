#pragma once
// LCM channel names: the bus contract between the services.

namespace ofn::channels {
inline constexpr const char* kNavState = "NAV_STATE";
inline constexpr const char* kActuatorCmd = "ACTUATOR_CMD";
inline constexpr const char* kSimClock = "SIM_CLOCK";
inline constexpr const char* kMission = "MISSION";
inline constexpr const char* kVirtualObstacles = "VIRTUAL_OBSTACLES";
inline constexpr const char* kLidarRaw = "LIDAR_RAW";
inline constexpr const char* kScanWorld = "SCAN_WORLD";
inline constexpr const char* kScannerStatus = "SCANNER_STATUS";
inline constexpr const char* kObstacleGrid = "OBSTACLE_GRID";
inline constexpr const char* kCuboids = "CUBOIDS";
inline constexpr const char* kGlobalPath = "GLOBAL_PATH";
inline constexpr const char* kNarrowPassages = "NARROW_PASSAGES";
inline constexpr const char* kRefTraj = "REF_TRAJ";
inline constexpr const char* kSolverStats = "SOLVER_STATS";
inline constexpr const char* kControlStatus = "CONTROL_STATUS";
inline constexpr const char* kHeartbeatPrefix = "HEARTBEAT_";
}  // namespace ofn::channels
