#pragma once
// The command line of every program of the project, one convention
// (docs/ARCHITECTURE.md, "Command lines"):
//   --help     the usage on stdout, exit code 0; every option's description
//              ends with its default, "(default: X)" ("(default: off)" for
//              a flag, "(default: none)" for a value nothing sets), unless
//              the description says it itself or the option is required;
//   --version  "<program> <version>" on stdout, exit code 0;
//   a usage error (unknown option, missing or bad value): one line
//              "<program>: error: <what is wrong> (see --help)" on stderr,
//              exit code 2, which a launcher never restarts.
// A program makes a CommandLine, adds its options and calls
// parse_command_line(); nothing else is needed.

#include <optional>
#include <string>

#include <CLI/CLI.hpp>

namespace ofn {

/// Exit codes of every program: 2 for a usage or input error (bad command
/// line, configuration or scenario), which a restart cannot mend; 1 for a
/// failure at run time (the bus cannot be opened, an unexpected exception),
/// which a restart may.
constexpr int kExitInputError = 2;
constexpr int kExitRuntimeError = 1;

/// The project's version: CMake's project version, followed by the
/// source's `git describe` when the build was configured in a git checkout,
/// e.g. "0.1.0 (git ecda934)". The describe is that of the configure run:
/// a later commit shows once CMake runs again.
const std::string& version();

/// A program's CLI11 application with the convention above. Options added
/// to it capture their variable's value as the default shown in --help.
class CommandLine : public CLI::App {
 public:
  /// `program` is the executable's name (ofn_controller): it opens the
  /// usage, the version line and every error line.
  CommandLine(const std::string& program, const std::string& description);

  const std::string& program() const { return program_; }

 private:
  std::string program_;
};

/// Parses the command line. Returns the exit code to end with: 0 after
/// --help or --version, kExitInputError after a usage error (its one line
/// printed); nullopt to go on.
std::optional<int> parse_command_line(CommandLine& app, int argc, char** argv);

/// The one-line message of a usage error: "<program>: error: <what> (see
/// --help)", the newlines of a multi-line CLI11 message joined.
std::string usage_error_line(const std::string& program, const std::string& what);

/// Number checks whose complaint names the bound in a few digits
/// ("--max-time: expected a number > 0, got 'abc'"); CLI11's own
/// PositiveNumber and Range print the largest double in full.
CLI::Validator positive_number();
CLI::Validator non_negative_number();
/// A number in [low, high].
CLI::Validator number_between(double low, double high);

}  // namespace ofn
