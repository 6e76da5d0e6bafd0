#pragma once
// What the services say they lost: every heartbeat carries, per channel the
// service subscribes to, the counts its publishers' sequence numbers gave
// (received, lost, duplicated, unsequenced, publishers; since that process
// started). The flight report and the flight monitor feed each heartbeat
// here and read the totals per service and channel, added up over the
// restarts of a service (a heartbeat from another pid, or with a count
// below the last, starts a new process's counts on top of the old), and
// which of them lost or duplicated more since the last look. Pure: no bus,
// no clock.

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "ofn/common/sequence_tracker.hpp"
#include "ofn/heartbeat_t.hpp"

namespace ofn::report {

/// One service's counts on one channel.
struct InputTotal {
  std::string service;
  std::string channel;
  SequenceCounts counts;
  /// Since the last InputLossTally::grown() (what it returns only).
  int64_t new_lost = 0;
  int64_t new_duplicated = 0;
};

/// Messages its publishers numbered: the sequenced ones received once,
/// and the lost.
int64_t sequenced_sent(const SequenceCounts& counts);

/// "rh_optimizer NAV_STATE: 37 of 3049 lost (1.2 %), 2 duplicated".
std::string describe(const InputTotal& input);

/// What grew, one line per service, in the order given (grown()'s):
/// "mapper: NAV_STATE +94 lost (197 of 1900, 10.4 %); SCAN_WORLD +65 lost
/// (123 of 232, 53.0 %), +1 duplicated".
std::vector<std::string> growth_lines(const std::vector<InputTotal>& grown);

class InputLossTally {
 public:
  /// Services x channels held; a flood of made-up names beyond that is
  /// left out (counted by ignored()).
  static constexpr size_t kMaxEntries = 1024;

  /// One heartbeat's inputs.
  void heard(const heartbeat_t& heartbeat);
  /// Per service and channel, sorted by service, then channel.
  std::vector<InputTotal> totals() const;
  /// The inputs whose lost or duplicated count grew since the last call,
  /// with by how much.
  std::vector<InputTotal> grown();
  /// Heartbeat inputs left out for want of room.
  int64_t ignored() const { return ignored_; }

 private:
  struct Entry {
    int32_t pid = 0;
    SequenceCounts base;     // processes that ended
    SequenceCounts current;  // the process heard last
    int64_t shown_lost = 0;
    int64_t shown_duplicated = 0;
    SequenceCounts total() const;
  };
  std::map<std::pair<std::string, std::string>, Entry> entries_;
  int64_t ignored_ = 0;
};

}  // namespace ofn::report
