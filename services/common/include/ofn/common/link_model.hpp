#pragma once
// What the network between hosts does to a message on its way from one
// service to another. Flight code never has one: the bus is the bus. The
// lockstep simulator attaches one (ofn/sim/link_faults.hpp) to fly the
// whole stack over a lossy, slow link, deterministically, as `make faults`
// does with real processes and packet filters.

#include <cstddef>
#include <string>

namespace ofn {

class LinkModel {
 public:
  /// What becomes of one message on its way to one receiver.
  struct Delivery {
    bool arrives = true;
    double delay = 0.0;  // s after it was sent, when it arrives
  };

  virtual ~LinkModel() = default;
  /// Service `publisher` sends a message on `channel`.
  virtual void published(const std::string& publisher, const std::string& channel) = 0;
  /// What becomes of the message of `bytes` bytes on `channel` now being
  /// delivered, on its way to service `receiver`.
  virtual Delivery deliver(const std::string& receiver, const std::string& channel,
                           std::size_t bytes) = 0;
};

}  // namespace ofn
