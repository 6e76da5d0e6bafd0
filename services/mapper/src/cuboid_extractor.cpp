#include "ofn/mapper/cuboid_extractor.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <tuple>

namespace ofn::mapping {
namespace {

/// Inclusive cell bounds of a set of blob cells and the highest top among them.
struct CellRect {
  int row_min = 0;
  int col_min = 0;
  int row_max = 0;
  int col_max = 0;
  float top = 0;
  int rows() const { return row_max - row_min + 1; }
  int cols() const { return col_max - col_min + 1; }
};

using CellIter = std::vector<int>::iterator;

CellRect bounds_of(const Heightfield& grid, CellIter begin, CellIter end) {
  CellRect rect;
  rect.row_min = grid.rows;
  rect.col_min = grid.cols;
  rect.row_max = -1;
  rect.col_max = -1;
  for (auto it = begin; it != end; ++it) {
    const int row = *it / grid.cols, col = *it % grid.cols;
    rect.row_min = std::min(rect.row_min, row);
    rect.row_max = std::max(rect.row_max, row);
    rect.col_min = std::min(rect.col_min, col);
    rect.col_max = std::max(rect.col_max, col);
    rect.top = std::max(rect.top, grid.top[static_cast<size_t>(*it)]);
  }
  return rect;
}

}  // namespace

std::vector<Cuboid> CuboidExtractor::extract(const Heightfield& filtered,
                                             const TopSeen& top_seen) const {
  if (filtered.empty()) return {};
  if (filtered.rows < 0 || filtered.cols < 0 ||
      filtered.top.size() != static_cast<size_t>(filtered.rows) * filtered.cols)
    throw std::invalid_argument("heightfield: top has " + std::to_string(filtered.top.size()) +
                                " cells, rows * cols = " + std::to_string(filtered.rows) + " * " +
                                std::to_string(filtered.cols));
  if (!(filtered.resolution > 0) || !std::isfinite(filtered.resolution))
    throw std::invalid_argument("heightfield: resolution must be a positive number");

  const double res = filtered.resolution;
  const double cell_area = res * res;
  const int rows = filtered.rows, cols = filtered.cols;
  const auto is_obstacle = [&](int index) {
    return filtered.top[static_cast<size_t>(index)] > config_.height_threshold;
  };

  std::vector<CellRect> pieces;
  // A work list instead of recursion: both the flood fill and the halving
  // would otherwise recurse once per cell / per level on large blobs.
  struct Part {
    CellIter begin, end;
    int depth;
  };
  std::vector<Part> parts;
  const auto split_blob = [&](CellIter blob_begin, CellIter blob_end) {
    parts.assign(1, Part{blob_begin, blob_end, 0});
    while (!parts.empty()) {
      const Part part = parts.back();
      parts.pop_back();
      const CellRect rect = bounds_of(filtered, part.begin, part.end);
      const auto blob_cells = static_cast<double>(part.end - part.begin);
      const double fill = blob_cells / (static_cast<double>(rect.rows()) * rect.cols());
      const bool along_rows = rect.rows() >= rect.cols();
      const int long_cells = along_rows ? rect.rows() : rect.cols();
      const bool split = fill < config_.min_fill && part.depth < config_.max_split_depth &&
                         long_cells >= 2 && long_cells * res >= 2 * config_.min_split_size;
      if (!split) {
        pieces.push_back(rect);
        continue;
      }
      const int cut = along_rows ? rect.row_min + rect.rows() / 2 : rect.col_min + rect.cols() / 2;
      const CellIter middle = std::partition(part.begin, part.end, [&](int index) {
        return (along_rows ? index / cols : index % cols) < cut;
      });
      // The bounds are tight, so both halves hold cells; guard anyway.
      if (middle != part.begin) parts.push_back(Part{part.begin, middle, part.depth + 1});
      if (middle != part.end) parts.push_back(Part{middle, part.end, part.depth + 1});
    }
  };

  std::vector<char> visited(filtered.top.size(), 0);
  std::vector<int> blob, frontier;
  for (int start = 0; start < rows * cols; ++start) {
    if (visited[static_cast<size_t>(start)] || !is_obstacle(start)) continue;
    blob.clear();
    frontier.assign(1, start);
    visited[static_cast<size_t>(start)] = 1;
    while (!frontier.empty()) {
      const int index = frontier.back();
      frontier.pop_back();
      blob.push_back(index);
      const int row = index / cols, col = index % cols;
      for (int d_row = -1; d_row <= 1; ++d_row) {
        for (int d_col = -1; d_col <= 1; ++d_col) {
          const int n_row = row + d_row, n_col = col + d_col;
          if (!filtered.inside(n_row, n_col)) continue;
          const int neighbour = n_row * cols + n_col;
          if (visited[static_cast<size_t>(neighbour)] || !is_obstacle(neighbour)) continue;
          visited[static_cast<size_t>(neighbour)] = 1;
          frontier.push_back(neighbour);
        }
      }
    }
    if (static_cast<double>(blob.size()) * cell_area < config_.min_area) continue;
    split_blob(blob.begin(), blob.end());
  }

  std::vector<Cuboid> cuboids;
  cuboids.reserve(pieces.size());
  for (const CellRect& rect : pieces) {
    Cuboid cuboid;
    const double min_north = filtered.origin_north + rect.row_min * res;
    const double min_east = filtered.origin_east + rect.col_min * res;
    const double max_north = filtered.origin_north + (rect.row_max + 1) * res;
    const double max_east = filtered.origin_east + (rect.col_max + 1) * res;
    double top_altitude = config_.ground_altitude + rect.top;
    if (top_seen && !top_seen(min_north, min_east, max_north, max_east, top_altitude)) {
      cuboid.top_observed = false;
      // What the sensor saw may be only the lower part of the obstacle.
      top_altitude = std::max(top_altitude, config_.ground_altitude + config_.ceiling);
    }
    cuboid.min = Vec3(min_north, min_east, -top_altitude);
    cuboid.max = Vec3(max_north, max_east, -config_.ground_altitude);
    cuboids.push_back(cuboid);
  }
  std::sort(cuboids.begin(), cuboids.end(), [](const Cuboid& a, const Cuboid& b) {
    return std::make_tuple(a.min.x(), a.min.y(), a.max.x(), a.max.y(), a.min.z()) <
           std::make_tuple(b.min.x(), b.min.y(), b.max.x(), b.max.y(), b.min.z());
  });
  return cuboids;
}

}  // namespace ofn::mapping
