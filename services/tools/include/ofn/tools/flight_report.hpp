#pragma once
// Turns an LCM log of a flight into CSV files per channel (SI, each header
// naming its unit: "north [m]"), a summary
// (summary.json and a one-screen text) and, through plot_flight.py, the
// flight figure. Used by `ofn_flight_report` and by the lockstep runner.

#include <optional>
#include <string>

#include "ofn/common/scenario.hpp"
#include "ofn/tools/flight_analysis.hpp"

namespace ofn::report {

struct ReportResult {
  FlightSummary summary;
  std::string text;  // one-screen summary for the terminal
  size_t events = 0;
  size_t undecodable = 0;
  /// Least distance from the flown path to a real surface, the obstacles
  /// and the ground (m); none without a scenario.
  std::optional<double> min_clearance;
  Verdict verdict;  // the benchmark rule applied to this flight
};

/// Reads `log_path`, writes CSV and summary files into `out_dir` (created if
/// needed). `scenario`, if given, supplies the timing gates, the true world
/// and the display unit; limits come from the logged MISSION;
/// `pseudo_control_bound` is the bound of the controller that flew.
/// Throws std::runtime_error if the log cannot be read.
ReportResult write_flight_report(const std::string& log_path, const std::string& out_dir,
                                 const std::optional<Scenario>& scenario,
                                 const PseudoControlBound& pseudo_control_bound);

}  // namespace ofn::report
