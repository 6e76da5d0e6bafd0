#pragma once
// Binds the view state to the bus: every channel the page draws in (checked
// by the node, then by the view state), a JSON snapshot out to the HTTP side
// at a fixed rate of the node's clock. Publishes nothing but its heartbeat.

#include <string>

#include "ofn/common/node.hpp"
#include "ofn/viewer/snapshot_hub.hpp"
#include "ofn/viewer/view_state.hpp"

namespace ofn::viewer {

class ViewerService {
 public:
  /// `snapshot_rate` in Hz of the clock; snapshots go to `hub`.
  ViewerService(lcm::LCM& lcm, const Clock& clock, ViewStateConfig config, SnapshotHub& hub,
                double snapshot_rate);
  Node& node() { return node_; }
  const ViewState& view() const { return view_; }
  /// Renders the view into the hub now (also done by the timer).
  void publish_snapshot();

 private:
  void take(const std::string& channel, const std::string& rejection);

  Node node_;
  ViewState view_;
  SnapshotHub& hub_;
};

}  // namespace ofn::viewer
