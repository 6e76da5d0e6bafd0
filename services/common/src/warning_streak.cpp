#include "ofn/common/warning_streak.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace ofn {

std::vector<std::string> WarningStreak::warn(double t, const std::string& kind,
                                             const std::string& text, double figure) {
  std::vector<std::string> lines;
  if (!kind_.empty() && kind == kind_) {
    ++repeats_;
    last_ = t;
    if (std::isfinite(figure)) worst_ = std::max(worst_, figure);
    return lines;
  }
  lines = clear(t);
  kind_ = kind;
  first_ = last_ = t;
  worst_ = std::isfinite(figure) ? figure : 0.0;
  repeats_ = 0;
  lines.push_back(text);
  return lines;
}

std::vector<std::string> WarningStreak::clear(double t) {
  std::vector<std::string> lines;
  if (!kind_.empty() && repeats_ > 0) lines.push_back(summary(t));
  kind_.clear();
  repeats_ = 0;
  return lines;
}

std::string WarningStreak::summary(double t) const {
  char span[64], worst[32], end[40];
  std::snprintf(span, sizeof span, " more from t=%.2f to %.2f s (", first_, last_);
  std::snprintf(worst, sizeof worst, " %.3g)", worst_);
  std::snprintf(end, sizeof end, ", over at t=%.2f s", t);
  return kind_ + ": " + std::to_string(repeats_) + span + figure_name_ + worst + end;
}

}  // namespace ofn
