#include "ofn/tools/heartbeat_watch.hpp"

#include <cmath>
#include <stdexcept>

namespace ofn::report {

HeartbeatWatch::HeartbeatWatch(double silence) : silence_(silence) {
  if (!(std::isfinite(silence) && silence > 0))
    throw std::invalid_argument("heartbeat watch: the silence must be a positive time");
}

void HeartbeatWatch::heard(const std::string& service, double now) {
  services_[service].last = now;
}

bool HeartbeatWatch::heard(const std::string& service, const std::string& named, double now) {
  if (named != service) return false;
  heard(service, now);
  return true;
}

HeartbeatChanges HeartbeatWatch::check(double now) {
  HeartbeatChanges changes;
  for (auto& [name, entry] : services_) {
    const bool quiet = now - entry.last >= silence_;
    if (quiet && !entry.silent) changes.silent.push_back(name);
    if (!quiet && entry.silent) changes.back.push_back(name);
    entry.silent = quiet;
  }
  return changes;
}

std::vector<std::string> HeartbeatWatch::silent() const {
  std::vector<std::string> names;
  for (const auto& [name, entry] : services_)
    if (entry.silent) names.push_back(name);
  return names;
}

}  // namespace ofn::report
