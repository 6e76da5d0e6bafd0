#pragma once
// Deterministic lockstep execution: every service in one process on one
// memq:// LCM, time advanced by a ManualClock from one timer deadline to
// the next, all messages delivered before time moves on. The same inputs
// give the same bus traffic, bit for bit, as fast as the CPU allows.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "ofn/common/clock.hpp"
#include "ofn/common/node.hpp"

namespace ofn::sim {

class Lockstep {
 public:
  Lockstep();
  lcm::LCM& lcm() { return lcm_; }
  ManualClock& clock() { return clock_; }

  void add(Node& node) { nodes_.push_back(&node); }
  const std::vector<Node*>& nodes() const { return nodes_; }

  /// Records every message, stamped with clock time, into an LCM log file.
  void record(const std::string& log_path);

  /// Runs until `stop()` returns true (checked after each time step) or the
  /// clock passes `end`. Returns true if `stop` ended the run.
  bool run(Utime end, const std::function<bool()>& stop = {});

  int64_t steps() const { return steps_; }
  int64_t messages() const { return messages_; }

 private:
  static void on_any(const lcm::ReceiveBuffer* rbuf, const std::string& channel, Lockstep* self);
  void deliver_all();

  lcm::LCM lcm_;
  ManualClock clock_;
  std::vector<Node*> nodes_;
  std::unique_ptr<lcm::LogFile> log_;
  int64_t steps_ = 0;
  int64_t messages_ = 0;
};

}  // namespace ofn::sim
