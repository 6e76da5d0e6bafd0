#pragma once
// A safety radius that grows with the tracking error. The RH optimiser
// keeps its plans R_s (plus clearance_margin) and their stops 0.9 R_s from
// mapped surfaces, and the verdict fails a flight at 0.8 R_s: the vehicle
// may stray 0.6 m (R_s 20 ft) from a stop before it breaks the rule. In
// calm air it strays a tenth of that (the largest position error of a
// dense calm flight is 0.10-0.24 m); in gusts 1-3 m, and the dense fields
// at 10 and 15 kt broke the clearance where the vehicle was blown towards
// an obstacle beside a stop. The tube widens every clearance the optimiser
// plans and checks with by the largest position error the controller
// reported over the last `window` seconds, less `onset` (what the fixed
// margins already cover), at most `max_extra`. Calm flights stay below the
// onset and are unchanged.
// Pure core: SI units, the caller's time (the messages' stamps).

#include <deque>
#include <utility>

#include "ofn/common/frames.hpp"

namespace ofn::rh {

struct TrackingTubeSettings {
  bool enabled = true;
  double window = 10.0;    // s of position errors the largest is taken over
  double onset = 0.5;      // m of error the fixed margins cover: no widening up to it
  double max_extra = 3.0;  // m; the most the clearance is widened by
};

class TrackingTube {
 public:
  explicit TrackingTube(TrackingTubeSettings settings = {}) : settings_(settings) {}

  /// One CONTROL_STATUS position error (reference - vehicle, m) stamped
  /// `time` (s). Non-finite errors or times are ignored. A time before the
  /// newest one counts as the newest (a message reordered on the link);
  /// one more than a window before it starts a new record (a restarted
  /// clock).
  void add(double time, const Vec3& position_error);
  /// m, the largest error over the window ending at the newest sample (0
  /// with none): a controller that falls silent leaves the last tube in
  /// place rather than letting it shrink.
  double largest_error() const;
  /// m to add to the safety radius: largest_error() less the onset, within
  /// [0, max_extra]; 0 when disabled.
  double extra_clearance() const;
  void reset() { samples_.clear(); }
  const TrackingTubeSettings& settings() const { return settings_; }

 private:
  TrackingTubeSettings settings_;
  // (time, error norm), times increasing and norms decreasing: the front is
  // the window's largest (a monotonic queue: O(1) per sample).
  std::deque<std::pair<double, double>> samples_;
};

}  // namespace ofn::rh
