#pragma once
// Which services has the ground station stopped hearing? Every service
// sends a heartbeat once a second of its clock. A process that died, hangs
// or is stopped falls silent; so does every follower of the simulation
// clock when vehicle_sim stops. The flight monitor feeds each heartbeat it
// receives here, with the wall time, and asks now and then which services
// have fallen silent for `silence` seconds and which were heard again after
// that. Wall time, not clock time: a dead vehicle_sim stops the simulation
// clock itself. Pure: no bus, no clock of its own.

#include <map>
#include <string>
#include <vector>

namespace ofn::report {

struct HeartbeatChanges {
  std::vector<std::string> silent;  // fell silent since the last check
  std::vector<std::string> back;    // heard again after being reported silent
};

class HeartbeatWatch {
 public:
  /// `silence`: seconds without a heartbeat after which a service that
  /// was heard counts as silent. Throws std::invalid_argument unless > 0.
  explicit HeartbeatWatch(double silence);

  /// A heartbeat from `service` received at wall time `now`, s.
  void heard(const std::string& service, double now);
  /// A heartbeat on `service`'s channel whose own service field says
  /// `named`: a sign of life only when the two agree (one naming another
  /// service is a stranger's, and kept a dead RH optimiser "heard" under
  /// the bus fuzz). Returns whether it counted.
  bool heard(const std::string& service, const std::string& named, double now);
  /// The changes since the last check, each list sorted by name. A service
  /// never heard is never reported.
  HeartbeatChanges check(double now);
  /// The services silent now (as of the last check), sorted by name.
  std::vector<std::string> silent() const;

 private:
  struct Entry {
    double last = 0;  // s, wall time of the last heartbeat
    bool silent = false;
  };
  double silence_;
  std::map<std::string, Entry> services_;
};

}  // namespace ofn::report
