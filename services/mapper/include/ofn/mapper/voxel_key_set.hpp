#pragma once
// A set of voxel keys (three 16-bit indices packed into one integer) for the
// per-scan bookkeeping of the occupancy map: which voxels a scan hit, which
// its rays cross. Open addressing with linear probing in one array that is
// kept between scans, so that once it has grown a scan allocates nothing
// (OctoMap's own KeySet allocates a node per key and frees them all again).
// Keys are visited in the order they were first inserted.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace ofn::mapping {

class VoxelKeySet {
 public:
  /// Packs three 16-bit voxel indices; the result is never kEmpty.
  static std::uint64_t pack(std::uint16_t x, std::uint16_t y, std::uint16_t z) {
    return static_cast<std::uint64_t>(x) << 32 | static_cast<std::uint64_t>(y) << 16 | z;
  }
  static std::uint16_t x_of(std::uint64_t key) { return static_cast<std::uint16_t>(key >> 32); }
  static std::uint16_t y_of(std::uint64_t key) { return static_cast<std::uint16_t>(key >> 16); }
  static std::uint16_t z_of(std::uint64_t key) { return static_cast<std::uint16_t>(key); }

  /// True when the key was not in the set yet.
  bool insert(std::uint64_t key) {
    if (2 * (keys_.size() + 1) > slots_.size()) grow();
    const std::size_t i = probe(key);
    if (slots_[i] == key) return false;
    slots_[i] = key;
    keys_.push_back(key);
    return true;
  }
  bool contains(std::uint64_t key) const { return !slots_.empty() && slots_[probe(key)] == key; }
  /// Empties the set and keeps its memory.
  void clear() {
    if (keys_.size() * 8 < slots_.size()) {
      // Few keys in a large table: clear their slots only, newest first.
      // The slots a key's probe passes over were taken by keys inserted
      // before it, so they are all still there when it is looked up.
      for (auto key = keys_.rbegin(); key != keys_.rend(); ++key) slots_[probe(*key)] = kEmpty;
    } else {
      std::fill(slots_.begin(), slots_.end(), kEmpty);
    }
    keys_.clear();
  }
  std::size_t size() const { return keys_.size(); }
  bool empty() const { return keys_.empty(); }
  /// The keys in the order of their first insertion.
  const std::vector<std::uint64_t>& keys() const { return keys_; }

 private:
  // A packed key uses 48 bits: all ones never occurs.
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};

  // The slot holding `key`, or else the empty slot that ends its probe
  // sequence (linear probing).
  std::size_t probe(std::uint64_t key) const {
    std::size_t i = slot_of(key);
    while (slots_[i] != kEmpty && slots_[i] != key) i = (i + 1) & mask_;
    return i;
  }
  std::size_t slot_of(std::uint64_t key) const {
    // Fibonacci hashing: neighbouring voxels spread over the table.
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_);
  }
  void grow() {
    const std::size_t capacity = slots_.empty() ? 1024 : 2 * slots_.size();
    int bits = 0;
    while ((std::size_t{1} << bits) < capacity) ++bits;
    shift_ = 64 - bits;
    mask_ = (std::size_t{1} << bits) - 1;
    slots_.assign(std::size_t{1} << bits, kEmpty);
    for (const std::uint64_t key : keys_) slots_[probe(key)] = key;
  }

  std::vector<std::uint64_t> slots_;
  std::vector<std::uint64_t> keys_;
  std::size_t mask_ = 0;
  int shift_ = 64;
};

}  // namespace ofn::mapping
