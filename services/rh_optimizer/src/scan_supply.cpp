#include "ofn/rh_optimizer/scan_supply.hpp"

#include <cmath>
#include <cstdio>

namespace ofn::rh {

void ScanSupply::received(double t, int64_t index) {
  if (!std::isfinite(t)) return;
  // A scanner that starts counting again (a restart) starts a new window.
  if (!arrivals_.empty() && index <= arrivals_.back().index) arrivals_.clear();
  arrivals_.push_back({t, index});
  last_arrival_ = t;
  any_ = true;
}

bool ScanSupply::starved(double t) {
  if (!settings_.enabled || !any_) {
    starved_ = false;
    why_.clear();
    return false;
  }
  while (!arrivals_.empty() && arrivals_.front().t < t - settings_.window) arrivals_.pop_front();
  char text[96];
  const double silence = t - last_arrival_;
  if (silence > settings_.max_silence) {
    std::snprintf(text, sizeof text, "no scan for %.1f s", silence);
    share_ = 0.0;
    why_ = text;
    return starved_ = true;
  }
  const int64_t due = arrivals_.empty() ? 0 : arrivals_.back().index - arrivals_.front().index + 1;
  if (due < settings_.min_expected) {
    // Too few due to judge by the share; the silence rule above still holds.
    if (!starved_) why_.clear();
    return starved_;
  }
  share_ = static_cast<double>(arrivals_.size()) / static_cast<double>(due);
  if (share_ < settings_.starved_below)
    starved_ = true;
  else if (share_ > settings_.fed_above)
    starved_ = false;
  if (starved_) {
    std::snprintf(text, sizeof text, "%.0f %% of the scans of the last %.0f s arrived",
                  100.0 * share_, settings_.window);
    why_ = text;
  } else {
    why_.clear();
  }
  return starved_;
}

}  // namespace ofn::rh
