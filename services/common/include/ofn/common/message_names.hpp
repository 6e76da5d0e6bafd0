#pragma once
// Names of the messages' enumerations, as lcm-spy and the .lcm files spell
// them: for logs, progress lines and the live view.

namespace ofn {

const char* control_mode_name(int mode);     // control_status_t::mode
const char* ref_traj_mode_name(int mode);    // ref_traj_t::mode
const char* solver_status_name(int status);  // solver_stats_t::status
const char* path_status_name(int status);    // global_path_t::status

}  // namespace ofn
