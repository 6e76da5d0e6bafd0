#pragma once
// Passages the RH optimiser cannot fly through, for the global planner to
// route round. The global planner places its nodes R_s outside the
// cuboids; the optimiser keeps R_s plus its clearance margin from the
// mapped cells. The cuboids bound those cells, so the two mostly agree,
// but a gap between two cuboids a little wider than 2 R_s can be narrower
// than 2 (R_s + margin) in the cells (or narrower in the cells than the
// boxes say where a box was re-fitted): the planner then keeps offering a
// route the optimiser cannot fly, the vehicle stops in front of the gap and
// the dead-end recovery looks round, gets the same route back, and in the
// end gives up (dense field seed 158). A route point is a pinch when no
// point of the plane across the route within `max_shift` of it has the
// optimiser's clearance: every trajectory near the route has to cross that
// plane, and none can cross it there.
// Pure core: world NED, SI.

#include <optional>
#include <vector>

#include "ofn/common/frames.hpp"
#include "ofn/rh_optimizer/rh_optimizer.hpp"

namespace ofn::rh {

struct PassageSettings {
  bool enabled = true;
  double look_distance = 60.0;  // m along the route from its start that are checked
  double max_shift = 3.0;       // m across the route a trajectory may pass from its points
  double max_extent = 40.0;     // m up and down from a pinch searched for more of it
  double extent_step = 1.0;     // m between the altitudes of that search
  int max_passages = 32;        // remembered per mission; the oldest go first
};

/// A region no route should pass through: a vertical cylinder round the
/// column of altitudes in which the gap is too narrow, and a search step
/// more above and below.
struct NarrowPassage {
  Vec3 centre = Vec3::Zero();  // m, world NED: the middle of that column
  double radius = 0;           // m, horizontal: any route through the pinch passes within it
  double half_height = 0;      // m above and below the centre
  double clearance = 0;        // m, the most the pinch offers where found (less than required)
};

/// The first pinch along `route` (world NED, first point where the route
/// starts) within settings.look_distance of its start: a point at which
/// no point of the plane across the route within settings.max_shift has
/// `required` clearance. Found by climbing the clearance gradient within
/// that plane. The pinch's column: every altitude within
/// settings.max_extent above and below at which the gap, crossed level
/// within max_shift, is too narrow as well (searched every extent_step).
/// A pinch round the route's start is passed over (the
/// vehicle stopped in a narrow spot: routes may leave it). nullopt when
/// every point can be passed, for an empty query or for fewer than two
/// points.
std::optional<NarrowPassage> find_narrow_passage(const ClearanceQuery& clearance,
                                                 const std::vector<Vec3>& route, double required,
                                                 const PassageSettings& settings = {});

/// Where a stop meant for `point` can be made: the nearest point of the
/// horizontal disc within `max_shift` of it that has `required` clearance
/// (sampled every 0.5 m nearest first, then climbed from the widest
/// sample), `point` itself when it has. nullopt when the disc has no room,
/// for an empty query or a non-finite point. The one search both the
/// route check (find_cramped_stop) and the escape leg's end use: a corner
/// the check passes is one the escape finds room at.
std::optional<Vec3> room_to_stop(const ClearanceQuery& clearance, const Vec3& point,
                                 double required, double max_shift);

/// A point at which a route must stop (an escape leg of the dead-end
/// recovery ends at the route's first corner, from rest to rest) where
/// room_to_stop finds no room within settings.max_shift: no plan can end
/// there, and an escape to it would stall look after look. The zone: round
/// the stop, radius max_shift + 0.5 m (the disc without room), over the
/// column of altitudes in which there is no room either, as for a pinch;
/// its clearance is the most the disc offers. nullopt when there is room.
std::optional<NarrowPassage> find_cramped_stop(const ClearanceQuery& clearance, const Vec3& stop,
                                               double required,
                                               const PassageSettings& settings = {});

/// The passages found in one mission, for the global planner.
class PassageMemory {
 public:
  explicit PassageMemory(int capacity = 32) : capacity_(capacity) {}
  /// Adds `passage` unless its centre lies within a remembered one; drops
  /// the oldest beyond the capacity. True if it was added.
  bool add(const NarrowPassage& passage);
  void clear() { passages_.clear(); }
  const std::vector<NarrowPassage>& passages() const { return passages_; }

 private:
  int capacity_;
  std::vector<NarrowPassage> passages_;
};

}  // namespace ofn::rh
