#pragma once
// What the scanner has not seen is not assumed free right behind what it has
// seen. The grid holds only surfaces the LIDAR hit: of a cube seen from the
// front, only its front face; its sides and back come into view only once
// the vehicle is beside or past it, and with the scanner looking ahead
// (yaw sweep of +-20 deg) that can be when the vehicle is already turning
// back towards the leg right behind it. So the optimiser treats the hidden
// space behind every obstacle cell that stands above the vehicle as
// obstacle, up to `depth` metres away from the vehicle along the line of
// sight, stopping at the first cell a beam has crossed near flight
// altitude (seen free there, so the obstacle does not reach it).
// Pure core: the visibility record is fed from the scans by the service.

#include <cstdint>
#include <unordered_map>
#include <unordered_set>

#include "ofn/common/frames.hpp"
#include "ofn/map/heightfield.hpp"

namespace ofn::rh {

/// Horizontal cells (world-fixed, `resolution` square) that a LIDAR beam
/// has crossed within `band` metres of the vehicle's altitude.
class VisibilityRecord {
 public:
  /// `max_reach`: metres of a beam that count, horizontally from its
  /// origin; a longer one (no LIDAR sees that far) counts to there as a
  /// beam without a hit, so that the cells one beam adds stay bounded
  /// (2 max_reach / resolution) whatever its end.
  explicit VisibilityRecord(double resolution = 1.0, double band = 3.0, double max_reach = 400.0)
      : resolution_(resolution), band_(band), max_reach_(max_reach) {}

  /// One beam from the sensor at `origin` to `end` (world NED); `hit`: the
  /// end cell holds the obstacle and is not marked. `vehicle_altitude` is
  /// the altitude (-z) the band is centred on.
  void add_beam(const Vec3& origin, const Vec3& end, bool hit, double vehicle_altitude);
  void set_max_reach(double metres) { max_reach_ = metres; }
  bool seen(double north, double east) const { return cells_.count(key(north, east)) > 0; }
  size_t size() const { return cells_.size(); }
  void clear() { cells_.clear(); }
  /// Drops cells farther than `radius` horizontally from `centre`, so the
  /// record stays the size of the neighbourhood on a long flight.
  void forget_beyond(const Vec3& centre, double radius);

 private:
  int64_t key(double north, double east) const;

  double resolution_;
  double band_;
  double max_reach_;
  std::unordered_set<int64_t> cells_;
};

/// Shadows once cast stay until a beam has seen through them. A shadow cast
/// from where the vehicle is now points away from it: passing beside a
/// cube seen from the front, the line of sight through its front face runs
/// sideways, the space behind the face (the cube's unseen body) is no
/// longer shadowed, and the optimiser turned back into it (bench4).
class ShadowMemory {
 public:
  explicit ShadowMemory(double resolution = 1.0) : resolution_(resolution) {}

  /// Remembers that the cell at (north, east) lies in the shadow of the
  /// obstacle cell at (occluder_north, occluder_east), `top` high.
  void remember(double north, double east, float top, double occluder_north, double occluder_east);
  /// Forgets the cells a beam has crossed and those whose occluder is no
  /// longer in `grid` as high, then raises every remembered cell of `grid`
  /// to its remembered height. Returns the cells raised.
  int apply(mapping::Heightfield& grid, const VisibilityRecord& visibility);
  void forget_beyond(const Vec3& centre, double radius);
  size_t size() const { return tops_.size(); }
  void clear() { tops_.clear(); }

 private:
  int64_t key(double north, double east) const;

  struct Shadow {
    float top = 0;
    double occluder_north = 0, occluder_east = 0;
  };
  double resolution_;
  std::unordered_map<int64_t, Shadow> tops_;
};

/// Raises the hidden cells behind every obstacle cell taller than
/// `vehicle_altitude` (m above ground), along the line of sight from the
/// vehicle, up to `depth` metres beyond the cell or to the first seen cell.
/// Cells within `near` metres of the vehicle cast no shadow. Returns the
/// number of cells raised.
/// With `memory`, every shadowed cell is also remembered there.
int cast_occlusion_shadows(mapping::Heightfield& grid, const VisibilityRecord& visibility,
                           const Vec3& vehicle_ned, double vehicle_altitude, double depth,
                           double near = 2.0, ShadowMemory* memory = nullptr);

/// An obstacle seen only at the edge of what the scanner has looked at may
/// go on into the space it has not: beside the path, outside the sweep, a
/// box's corner hit by the sweep's edge can be all that is seen of it, and
/// its top only where the beams grazed the corner (dense field 7: a 123 ft
/// box mapped as a 101 ft pillar at its corner and passed at 0.5 R_s). The
/// shadows cover what lies behind a face along the line of sight, not what
/// lies beside it. So every cell free in `grid` that no beam has crossed
/// near flight altitude, within `reach` metres of an obstacle cell of
/// `mapped` (top above `min_top`, m above ground) and no nearer to the
/// vehicle than that cell, is raised in `grid` (the same cells, `mapped`
/// with the shadows added) to `top`: its height is unknown. Cells nearer
/// than the obstacle are left alone: the beams that met it came through
/// them (a beam marks the cells it crosses only up to one short of its hit).
/// Shadows neither extend nor grow: they are unseen space taken as
/// obstacle already, and widening or raising them would close gaps and tops
/// the scanner has looked through or over. It lasts only
/// until a beam crosses the cell. Returns the number of cells raised.
int extend_into_unseen(const mapping::Heightfield& mapped, mapping::Heightfield& grid,
                       const VisibilityRecord& visibility, const Vec3& vehicle_ned, double reach,
                       float min_top, float top);

/// Every cell of `grid` lower than `top`, between `exempt` and `reach`
/// metres horizontally from the vehicle, that no beam has crossed near
/// flight altitude is raised to `top` (its height unknown): beside the
/// path, where the sweep has not looked, may stand what was never seen
/// (dense seed 412: a cylinder no beam crossed, passed at 0.78 R_s). Nearer
/// cells are left alone so that the vehicle never stands inside what is
/// raised (the optimiser does not solve from within half of R_s). Returns
/// the number of cells raised.
int raise_unseen_near(mapping::Heightfield& grid, const VisibilityRecord& visibility,
                      const Vec3& vehicle_ned, double exempt, double reach, float top);

}  // namespace ofn::rh
