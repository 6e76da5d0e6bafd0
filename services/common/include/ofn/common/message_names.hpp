#pragma once
// Names of the messages' enumerations, as lcm-spy and the .lcm files spell
// them: for logs, progress lines and the live view; and text from the bus
// made fit for a log line.

#include <cstddef>
#include <string>

namespace ofn {

const char* control_mode_name(int mode);     // control_status_t::mode
const char* ref_traj_mode_name(int mode);    // ref_traj_t::mode
const char* solver_status_name(int status);  // solver_stats_t::status
const char* path_status_name(int status);    // global_path_t::status

/// `text` from a message (a mission's name, a frame) as one printable line:
/// every byte outside ' '..'~' and every backslash written as \xNN, at most `max_chars` of
/// it, "..." after. A stranger's string cannot break a log line or a
/// terminal, however it was forged.
std::string printable(const std::string& text, size_t max_chars = 64);

}  // namespace ofn
