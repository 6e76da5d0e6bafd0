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
  /// Messages that decoded but failed the services' validation (a stranger
  /// on the bus, say), left out of the summary and the tables; the first
  /// one's channel and reason.
  size_t invalid = 0;
  std::string first_invalid;
  /// Whether the log was read with a keyring; the messages not signed by a
  /// role allowed to publish on their channel, left out; the first one's
  /// channel and reason.
  bool authenticated = false;
  size_t unauthenticated = 0;
  std::string first_unauthenticated;
  /// Least distance from the flown path to a real surface, the obstacles
  /// and the ground (m); none without a scenario.
  std::optional<double> min_clearance;
  Verdict verdict;  // the benchmark rule applied to this flight
};

/// Reads `log_path`, writes CSV and summary files into `out_dir` (created if
/// needed). `scenario`, if given, supplies the timing gates, the true world
/// and the display unit; limits come from the logged MISSION;
/// `pseudo_control_bound` is the bound of the controller that flew.
/// `bus_keyring`, if given, is a keyring directory of the authenticated bus
/// the log was recorded on (its policy.yaml and public keys): only what its
/// roles signed on their channels is read. `control_stops`, if given, are
/// the controller's actuator stops: the summary then tells how much of the
/// flight a channel was at one (ControlSaturation). Throws
/// std::invalid_argument if the log or the keyring cannot be read.
ReportResult write_flight_report(const std::string& log_path, const std::string& out_dir,
                                 const std::optional<Scenario>& scenario,
                                 const PseudoControlBound& pseudo_control_bound,
                                 const std::string& bus_keyring = "",
                                 const std::optional<ControlStops>& control_stops = std::nullopt);

}  // namespace ofn::report
