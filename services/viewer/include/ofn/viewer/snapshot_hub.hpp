#pragma once
// Hands the newest JSON snapshot from the bus thread to the HTTP threads:
// the bus side publishes, every page connection waits for a newer one.
// Pure: no sockets, no LCM.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>

namespace ofn::viewer {

class SnapshotHub {
 public:
  /// Replaces the current snapshot and wakes every waiting reader.
  void publish(std::string snapshot);
  /// The current snapshot and its sequence number (0: none yet, text "{}").
  std::pair<uint64_t, std::string> current() const;
  /// Waits up to `timeout` for a snapshot newer than `seen`, or for close().
  /// Returns the sequence number reached (== seen when none came) and sets
  /// `snapshot` when it is newer.
  uint64_t wait_newer(uint64_t seen, std::chrono::milliseconds timeout,
                      std::string& snapshot) const;
  /// Wakes every reader for good: the process is stopping.
  void close();
  bool closed() const;

 private:
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  std::string snapshot_ = "{}";
  uint64_t sequence_ = 0;
  bool closed_ = false;
};

}  // namespace ofn::viewer
