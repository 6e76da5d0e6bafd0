#include "ofn/viewer/snapshot_hub.hpp"

namespace ofn::viewer {

void SnapshotHub::publish(std::string snapshot) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    snapshot_ = std::move(snapshot);
    ++sequence_;
  }
  changed_.notify_all();
}

std::pair<uint64_t, std::string> SnapshotHub::current() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return {sequence_, snapshot_};
}

uint64_t SnapshotHub::wait_newer(uint64_t seen, std::chrono::milliseconds timeout,
                                 std::string& snapshot) const {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait_for(lock, timeout, [&] { return closed_ || sequence_ != seen; });
  if (sequence_ != seen) snapshot = snapshot_;
  return sequence_;
}

void SnapshotHub::close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
  }
  changed_.notify_all();
}

bool SnapshotHub::closed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return closed_;
}

}  // namespace ofn::viewer
