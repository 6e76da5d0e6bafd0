#include "ofn/mapper/obstacle_database.hpp"

#include <algorithm>

namespace ofn::mapping {

double footprint_overlap(const Cuboid& a, const Cuboid& b) {
  const auto footprint = [](const Cuboid& c) {
    return std::max(0.0, c.max.x() - c.min.x()) * std::max(0.0, c.max.y() - c.min.y());
  };
  const double smaller = std::min(footprint(a), footprint(b));
  if (!(smaller > 0)) return 0;
  const double north = std::min(a.max.x(), b.max.x()) - std::max(a.min.x(), b.min.x());
  const double east = std::min(a.max.y(), b.max.y()) - std::max(a.min.y(), b.min.y());
  if (north <= 0 || east <= 0) return 0;
  return north * east / smaller;
}

void ObstacleDatabase::update(const std::vector<Cuboid>& extracted, Utime now,
                              const std::function<bool(const Cuboid&)>& in_view) {
  const double step = config_.confidence_step;
  // An entry answers at most one extracted cuboid per cycle, so that the
  // adjacent pieces of a split blob stay separate entries.
  std::vector<char> claimed(entries_.size(), 0), removed(entries_.size(), 0);
  std::vector<ObstacleEntry> inserted;
  std::vector<size_t> matches;

  for (const Cuboid& cuboid : extracted) {
    matches.clear();
    for (size_t i = 0; i < entries_.size(); ++i)
      if (!claimed[i] && !removed[i] &&
          footprint_overlap(entries_[i].cuboid, cuboid) >= config_.match_overlap)
        matches.push_back(i);

    if (matches.empty()) {
      ObstacleEntry entry;
      entry.id = next_id_++;
      entry.cuboid = cuboid;
      entry.confidence = std::clamp(step, 0.0, 1.0);
      entry.first_seen = now;
      entry.last_seen = now;
      inserted.push_back(entry);
      ++inserted_;
      continue;
    }

    // entries_ is kept in id order, so the first match has the lowest id.
    ObstacleEntry& keeper = entries_[matches.front()];
    claimed[matches.front()] = 1;
    // A merged entry's history is the keeper's too: the oldest sighting and
    // the best confidence carry over.
    double confidence = keeper.confidence;
    for (size_t k = 1; k < matches.size(); ++k) {
      const ObstacleEntry& absorbed = entries_[matches[k]];
      confidence = std::max(confidence, absorbed.confidence);
      keeper.first_seen = std::min(keeper.first_seen, absorbed.first_seen);
      removed[matches[k]] = 1;
      ++merged_;
    }
    keeper.cuboid = cuboid;
    keeper.confidence = std::clamp(confidence + step, 0.0, 1.0);
    keeper.last_seen = now;
    keeper.misses = 0;
  }

  for (size_t i = 0; i < entries_.size(); ++i) {
    if (claimed[i] || removed[i]) continue;
    ObstacleEntry& entry = entries_[i];
    if (in_view && !in_view(entry.cuboid)) continue;
    ++entry.misses;
    entry.confidence = std::max(0.0, entry.confidence - step);
    if (entry.misses >= config_.retire_after_misses) {
      removed[i] = 1;
      ++retired_;
    }
  }

  size_t kept = 0;
  for (size_t i = 0; i < entries_.size(); ++i)
    if (!removed[i]) entries_[kept++] = entries_[i];
  entries_.resize(kept);
  // New ids are above every existing one: appending keeps the id order.
  entries_.insert(entries_.end(), inserted.begin(), inserted.end());
}

}  // namespace ofn::mapping
