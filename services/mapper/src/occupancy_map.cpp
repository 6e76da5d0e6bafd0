#include "ofn/mapper/occupancy_map.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include <octomap/OcTree.h>
#include <octomap/octomap.h>

#include "ofn/mapper/voxel_key_set.hpp"

namespace ofn::mapping {

namespace {

void require(bool ok, const char* field, const char* what) {
  if (!ok) throw std::invalid_argument(std::string("occupancy map: ") + field + " " + what);
}

bool finite(const Vec3& p) {
  return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z());
}

octomap::point3d to_point(const Vec3& p) {
  return octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()),
                          static_cast<float>(p.z()));
}

bool probability(double p) {
  return std::isfinite(p) && p > 0.0 && p < 1.0;
}

std::uint64_t pack(const octomap::OcTreeKey& key) {
  return VoxelKeySet::pack(key[0], key[1], key[2]);
}

octomap::OcTreeKey unpack(std::uint64_t packed) {
  return octomap::OcTreeKey(VoxelKeySet::x_of(packed), VoxelKeySet::y_of(packed),
                            VoxelKeySet::z_of(packed));
}

}  // namespace

// The key sets of one scan, kept so that their memory is reused.
struct OccupancyMap::ScanKeys {
  VoxelKeySet occupied;  // voxels holding a return
  VoxelKeySet ends;      // voxels rays are cast to
  VoxelKeySet free;      // voxels the rays cross
  octomap::KeyRay ray;
};

OccupancyMap::OccupancyMap(const OccupancyMapConfig& config) : config_(config) {
  require(std::isfinite(config.resolution) && config.resolution > 0, "resolution", "must be > 0");
  require(std::isfinite(config.max_range) && config.max_range > 0, "max_range", "must be > 0");
  require(probability(config.prob_hit) && config.prob_hit > 0.5, "prob_hit", "must be in (0.5, 1)");
  require(probability(config.prob_miss) && config.prob_miss < 0.5, "prob_miss",
          "must be in (0, 0.5)");
  require(probability(config.clamp_min), "clamp_min", "must be in (0, 1)");
  require(probability(config.clamp_max) && config.clamp_max > config.clamp_min, "clamp_max",
          "must be in (clamp_min, 1)");
  require(probability(config.occupied_threshold), "occupied_threshold", "must be in (0, 1)");
  require(std::isfinite(config.forget_radius) && config.forget_radius > 0, "forget_radius",
          "must be > 0");
  require(std::isfinite(config.ground_altitude), "ground_altitude", "must be finite");
  tree_ = std::make_unique<octomap::OcTree>(config.resolution);
  scan_keys_ = std::make_unique<ScanKeys>();
  tree_->setProbHit(config.prob_hit);
  tree_->setProbMiss(config.prob_miss);
  tree_->setClampingThresMin(config.clamp_min);
  tree_->setClampingThresMax(config.clamp_max);
  tree_->setOccupancyThres(config.occupied_threshold);
}

OccupancyMap::~OccupancyMap() = default;

void OccupancyMap::insert_scan(const Vec3& sensor_origin, const std::vector<Vec3>& hits,
                               const std::vector<Vec3>& free_ray_ends) {
  if (!finite(sensor_origin)) return;
  octomap::OcTree& tree = *tree_;
  ScanKeys& keys = *scan_keys_;
  const octomap::point3d origin = to_point(sensor_origin);
  const double max_range = config_.max_range;

  // Every voxel is updated at most once per scan, and a voxel that holds a
  // return in this scan is not also cleared by a neighbouring beam: dense
  // scans would otherwise count one observation many times. Since each
  // voxel is updated once, the order of the updates does not change the
  // tree.
  keys.occupied.clear();
  keys.ends.clear();
  const auto add_free_end = [&](const Vec3& end) {
    const Vec3 d = end - sensor_origin;
    const double range = d.norm();
    if (!(range > 0)) return;
    const Vec3 clipped = range > max_range ? Vec3(sensor_origin + d * (max_range / range)) : end;
    octomap::OcTreeKey key;
    if (tree.coordToKeyChecked(to_point(clipped), key)) keys.ends.insert(pack(key));
  };
  for (const Vec3& hit : hits) {
    if (!finite(hit)) continue;
    if ((hit - sensor_origin).norm() > max_range) {
      add_free_end(hit);  // the beam crossed max_range free; the return beyond is not trusted
      continue;
    }
    octomap::OcTreeKey key;
    if (tree.coordToKeyChecked(to_point(hit), key)) keys.occupied.insert(pack(key));
  }
  for (const Vec3& end : free_ray_ends)
    if (finite(end)) add_free_end(end);
  for (const std::uint64_t key : keys.occupied.keys()) keys.ends.insert(key);

  // Rays are cast to the centres of the end voxels (as OctoMap's discretised
  // insertion does), which collapses the many beams ending in one voxel.
  keys.free.clear();
  for (const std::uint64_t end : keys.ends.keys()) {
    if (!tree.computeRayKeys(origin, tree.keyToCoord(unpack(end)), keys.ray)) continue;
    for (const octomap::OcTreeKey& key : keys.ray) keys.free.insert(pack(key));
  }

  for (const std::uint64_t key : keys.free.keys())
    if (!keys.occupied.contains(key)) tree.updateNode(unpack(key), false);
  for (const std::uint64_t key : keys.occupied.keys()) tree.updateNode(unpack(key), true);
}

namespace {

// Keys of the voxel block covering a square column between two altitudes;
// z keys grow downwards (NED), so the top of the column is z_lo.
struct ColumnKeys {
  octomap::key_type x_lo, x_hi, y_lo, y_hi, z_lo, z_hi;
};

bool column_keys(const octomap::OcTree& tree, double north, double east, double half_size,
                 double alt_lo, double alt_hi, double ground_altitude, ColumnKeys& keys) {
  if (!std::isfinite(north) || !std::isfinite(east) || !std::isfinite(half_size) ||
      !std::isfinite(alt_lo) || !std::isfinite(alt_hi) || alt_hi < alt_lo)
    return false;
  // Bounds are pulled inwards by a hair so that a grid cell whose edges lie
  // on voxel faces maps to its own voxel column only, and a range starting
  // at a voxel face (e.g. the ground clearance) leaves the voxel below out.
  const double hair = 1e-6 * tree.getResolution();
  const double h = std::max(0.0, half_size - hair);
  const double z_top = -(alt_hi + ground_altitude), z_bottom = -(alt_lo + ground_altitude);
  const double z_mid = 0.5 * (z_top + z_bottom);
  return tree.coordToKeyChecked(north - h, keys.x_lo) &&
         tree.coordToKeyChecked(north + h, keys.x_hi) &&
         tree.coordToKeyChecked(east - h, keys.y_lo) &&
         tree.coordToKeyChecked(east + h, keys.y_hi) &&
         tree.coordToKeyChecked(std::min(z_mid, z_top + hair), keys.z_lo) &&
         tree.coordToKeyChecked(std::max(z_mid, z_bottom - hair), keys.z_hi);
}

// Visits the column's voxels from the top down, stopping when `visit`
// returns true; returns the key it stopped at.
template <class Visit>
bool find_in_column(const octomap::OcTree& tree, const ColumnKeys& k, Visit visit,
                    octomap::OcTreeKey& found) {
  for (unsigned z = k.z_lo; z <= k.z_hi; ++z)
    for (unsigned x = k.x_lo; x <= k.x_hi; ++x)
      for (unsigned y = k.y_lo; y <= k.y_hi; ++y) {
        const octomap::OcTreeKey key(static_cast<octomap::key_type>(x),
                                     static_cast<octomap::key_type>(y),
                                     static_cast<octomap::key_type>(z));
        if (visit(tree.search(key))) {
          found = key;
          return true;
        }
      }
  return false;
}

}  // namespace

double OccupancyMap::column_top(double north, double east, double half_size, double alt_lo,
                                double alt_hi, double min_probability) const {
  const octomap::OcTree& tree = *tree_;
  ColumnKeys k;
  if (!column_keys(tree, north, east, half_size, alt_lo, alt_hi, config_.ground_altitude, k))
    return -1.0;
  const double probability = std::isfinite(min_probability)
                                 ? std::clamp(min_probability, config_.occupied_threshold, 1.0)
                                 : config_.occupied_threshold;
  if (probability >= 1.0) return -1.0;
  const float threshold = octomap::logodds(probability);
  octomap::OcTreeKey found;
  const auto occupied = [threshold](const octomap::OcTreeNode* node) {
    return node != nullptr && node->getLogOdds() >= threshold;
  };
  if (!find_in_column(tree, k, occupied, found)) return -1.0;
  const double voxel_top_z = tree.keyToCoord(found[2]) - 0.5 * tree.getResolution();
  return -voxel_top_z - config_.ground_altitude;
}

bool OccupancyMap::column_seen_free(double north, double east, double half_size, double alt_lo,
                                    double alt_hi) const {
  const octomap::OcTree& tree = *tree_;
  ColumnKeys k;
  if (!column_keys(tree, north, east, half_size, alt_lo, alt_hi, config_.ground_altitude, k))
    return false;
  octomap::OcTreeKey found;
  const auto known_free = [&tree](const octomap::OcTreeNode* node) {
    return node != nullptr && !tree.isNodeOccupied(node);
  };
  return find_in_column(tree, k, known_free, found);
}

namespace {

// OctoMap 1.9's deleteNode() trips over its own invariant when a node loses
// its last child (the emptied parent is deleted with its child array still
// allocated: OctoMap issue #287), so far voxels are removed here with the
// tree's structural primitives instead: a subtree is first collapsed into a
// single leaf (pruneNode frees child arrays properly), then detached.
class FarVoxelRemover {
 public:
  FarVoxelRemover(octomap::OcTree& tree, double north, double east, double radius)
      : tree_(tree), north_(north), east_(east), radius_sq_(radius * radius) {}

  void run() {
    octomap::OcTreeNode* root = tree_.getRoot();
    if (!root) return;
    // The root spans the whole key range, centred on the coordinate origin.
    const double root_size = tree_.getResolution() * 65536.0;
    if (drop_all(root, 0.0, 0.0, root_size)) tree_.clear();
  }

 private:
  // Removes the far parts below `node` and tells whether everything below
  // it (or the node itself, for a leaf) is far, leaving that to the caller.
  bool drop_all(octomap::OcTreeNode* node, double north, double east, double size) {
    const double dn = std::abs(north - north_), de = std::abs(east - east_);
    if (!tree_.nodeHasChildren(node)) return dn * dn + de * de > radius_sq_;
    // Most of the tree lies wholly inside the circle (or wholly outside):
    // such a node is decided by its box, without visiting what is below it.
    // Every leaf centre below lies within the box, so the answer is the one
    // the leaves would give, and the inner occupancies are already up to
    // date (nodes are updated without lazy evaluation).
    const double half = 0.5 * size;
    const double far_n = dn + half, far_e = de + half;
    if (far_n * far_n + far_e * far_e <= radius_sq_) return false;
    const double near_n = std::max(0.0, dn - half), near_e = std::max(0.0, de - half);
    if (near_n * near_n + near_e * near_e > radius_sq_) return true;
    bool drop[8] = {};
    bool all = true;
    const double quarter = 0.25 * size;
    for (unsigned i = 0; i < 8; ++i) {
      if (!tree_.nodeChildExists(node, i)) continue;
      drop[i] = drop_all(tree_.getNodeChild(node, i), north + ((i & 1) ? quarter : -quarter),
                         east + ((i & 2) ? quarter : -quarter), 0.5 * size);
      all = all && drop[i];
    }
    if (all) return true;
    for (unsigned i = 0; i < 8; ++i) {
      if (!drop[i]) continue;
      collapse(tree_.getNodeChild(node, i));
      tree_.deleteNodeChild(node, i);
    }
    node->updateOccupancyChildren();
    return false;
  }

  // Turns a subtree into one leaf, so that deleting it frees everything.
  void collapse(octomap::OcTreeNode* node) {
    if (!tree_.nodeHasChildren(node)) return;
    for (unsigned i = 0; i < 8; ++i) {
      octomap::OcTreeNode* child = tree_.nodeChildExists(node, i) ? tree_.getNodeChild(node, i)
                                                                  : tree_.createNodeChild(node, i);
      collapse(child);
      child->setLogOdds(0.0f);
    }
    tree_.pruneNode(node);
  }

  octomap::OcTree& tree_;
  double north_, east_, radius_sq_;
};

}  // namespace

void OccupancyMap::forget_far(double vehicle_north, double vehicle_east) {
  if (!std::isfinite(vehicle_north) || !std::isfinite(vehicle_east)) return;
  FarVoxelRemover(*tree_, vehicle_north, vehicle_east, config_.forget_radius).run();
}

size_t OccupancyMap::num_nodes() const {
  return tree_->size();
}

size_t OccupancyMap::memory_bytes() const {
  return tree_->memoryUsage();
}

}  // namespace ofn::mapping
