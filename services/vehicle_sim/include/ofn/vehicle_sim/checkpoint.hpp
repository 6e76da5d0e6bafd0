#pragma once
// The simulated aircraft's state saved as it flies, so that a vehicle_sim
// that is killed and restarted resumes the same flight (the aircraft does
// not jump back to the course's start, and the clock goes on from where it
// stopped) instead of starting a new world under services that are flying
// the old one. Pure core: text in, text out, no files; the file helpers
// below are the shell's.
//
// The text is line-oriented, one key and its numbers per line, the first
// line naming the format and its version:
//
//   ofn_vehicle_checkpoint 1
//   time_us 41230000
//   ...
//
// Not saved: the wind's turbulence and the navigation noise (their random
// streams start again), the LIDAR sweep's phase and the virtual obstacles
// (the injector sends them again).

#include <cstdint>
#include <optional>
#include <string>

#include "ofn/rotorcraft_model/rotorcraft_model.hpp"

namespace ofn::vehicle {

struct VehicleCheckpoint {
  int64_t time_us = 0;    // clock time the state is valid for
  int64_t steps = 0;      // physics steps taken (SIM_CLOCK's step)
  bool released = false;  // the controller flies the vehicle (not the start hold)
  RotorcraftState state;
};

std::string checkpoint_to_text(const VehicleCheckpoint& checkpoint);

/// Parses checkpoint_to_text()'s output. Throws std::runtime_error naming
/// the line and what is wrong: an unknown or repeated key, a missing one, a
/// number that is not finite, an attitude that is not a unit quaternion.
VehicleCheckpoint checkpoint_from_text(const std::string& text);

/// Writes atomically (a temporary file beside `path`, then a rename): a
/// process killed mid-write leaves the previous checkpoint whole. Throws
/// std::runtime_error when the file cannot be written.
void write_checkpoint_file(const std::string& path, const VehicleCheckpoint& checkpoint);

/// nullopt when there is no file at `path`; throws std::runtime_error
/// (with the path) when there is one that cannot be read or parsed.
std::optional<VehicleCheckpoint> read_checkpoint_file(const std::string& path);

}  // namespace ofn::vehicle
