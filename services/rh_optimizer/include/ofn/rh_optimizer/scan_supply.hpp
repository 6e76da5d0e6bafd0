#pragma once
// Whether the map is being fed: the share of the scanner's scans that
// reach the RH optimiser. The obstacle grid is published on its own
// cadence and stays "fresh" while it is built from a trickle of scans; on
// a link losing 30 % of its datagrams one scan in twelve arrives, and a
// climb committed on a map that had seen too little of a wall's top came
// within 0.64 R_s of it (bench3, lockstep). Scans are numbered by the
// scanner, so the gaps in their numbers say how many never arrived,
// whatever lost them (the link, the sensor interface, a restart).
//
// Starved: fewer than `starved_below` of the scans of the last `window`
// seconds arrived (with at least `min_expected` due), or none for
// `max_silence` seconds; fed again above `fed_above`. Before the first
// scan nothing is judged (a scanner that never reported is not this
// watch's to find). Pure core: times in seconds.

#include <cstdint>
#include <deque>
#include <string>

namespace ofn::rh {

struct ScanSupplySettings {
  bool enabled = true;
  double window = 3.0;         // s of scans counted
  double starved_below = 0.2;  // share of the scans due that arrived
  double fed_above = 0.3;      // share again before the map counts as fed
  double max_silence = 1.0;    // s without a scan
  int min_expected = 10;       // scans due in the window before the share counts
};

class ScanSupply {
 public:
  explicit ScanSupply(ScanSupplySettings settings = {}) : settings_(settings) {}

  /// A scan numbered `index` arrived at time `t`.
  void received(double t, int64_t index);
  /// Whether the map is starved of scans at time `t` (updates the state).
  bool starved(double t);
  /// Share of the window's scans that arrived, at the last starved() call.
  double share() const { return share_; }
  /// Why it is starved, for the log and SOLVER_STATS ("" when fed).
  const std::string& why() const { return why_; }

 private:
  struct Arrival {
    double t;
    int64_t index;
  };
  ScanSupplySettings settings_;
  std::deque<Arrival> arrivals_;  // within the window, oldest first
  double last_arrival_ = -1.0;
  bool any_ = false, starved_ = false;
  double share_ = 1.0;
  std::string why_;
};

}  // namespace ofn::rh
