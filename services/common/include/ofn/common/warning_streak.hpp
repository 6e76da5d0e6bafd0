#pragma once
// One line for a streak of like warnings. A service that warns once per
// step (the RH optimiser at 10 Hz, each failed solve) prints hundreds of
// lines in a minute of trouble: a cul-de-sac flight printed 348, and the
// one line that said why the trouble began was lost among them. Here the
// first warning of a streak is logged in full, the ones of the same kind
// after it are counted, and the streak's end is logged as one summary line
// with the worst figure seen. What each step said is not lost: the service
// publishes it anyway (SOLVER_STATS), and the flight log keeps it.
// Pure: no logger, no clock; times in seconds of the caller's clock.

#include <string>
#include <utility>
#include <vector>

namespace ofn {

class WarningStreak {
 public:
  /// `figure_name` names the figure in the summary ("worst violation").
  explicit WarningStreak(std::string figure_name = "worst")
      : figure_name_(std::move(figure_name)) {}

  /// A warning of `kind` (a few words that name it, without numbers) at
  /// time `t`, its full `text`, and a figure to carry to the summary (its
  /// largest is reported, e.g. the worst constraint violation). Returns the
  /// lines to log now: the summary of a streak of another kind that this
  /// one ends, and `text` if it begins a streak; nothing for a repeat.
  std::vector<std::string> warn(double t, const std::string& kind, const std::string& text,
                                double figure);
  /// A step without a warning: ends the streak. Returns its summary when
  /// warnings were left out of the log, otherwise nothing.
  std::vector<std::string> clear(double t);
  /// Warnings left out of the log since the streak began.
  int repeats() const { return repeats_; }

 private:
  std::string summary(double t) const;

  std::string figure_name_;
  std::string kind_;  // empty: no streak
  double first_ = 0;  // s, the streak's first warning
  double last_ = 0;   // s, its latest
  double worst_ = 0;
  int repeats_ = 0;
};

}  // namespace ofn
