#pragma once
// What the network between hosts does to a message on its way from one
// service to another. Flight code never has one: the bus is the bus. The
// lockstep simulator attaches one (ofn/sim/link_loss.hpp) to fly the whole
// stack over a lossy link, deterministically, as `make faults` does with
// real processes and packet filters.

#include <cstddef>
#include <string>

namespace ofn {

class LinkModel {
 public:
  virtual ~LinkModel() = default;
  /// Service `publisher` sends a message on `channel`.
  virtual void published(const std::string& publisher, const std::string& channel) = 0;
  /// Whether service `receiver` gets the message of `bytes` bytes on
  /// `channel` now being delivered; false: it never arrives.
  virtual bool delivers(const std::string& receiver, const std::string& channel,
                        std::size_t bytes) = 0;
};

}  // namespace ofn
