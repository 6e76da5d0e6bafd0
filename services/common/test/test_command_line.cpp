// The command-line convention: defaults in --help, --version, one-line
// usage errors with exit code 2, and number checks that say their bound.

#include <gtest/gtest.h>

#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "ofn/common/command_line.hpp"

namespace ofn {
namespace {

// What a parse printed and returned.
struct Outcome {
  std::optional<int> code;
  std::string out, err;
};

Outcome parse(CommandLine& app, std::vector<std::string> args) {
  args.insert(args.begin(), app.program());
  std::vector<char*> argv;
  for (auto& arg : args) argv.push_back(arg.data());
  std::ostringstream out, err;
  auto* old_out = std::cout.rdbuf(out.rdbuf());
  auto* old_err = std::cerr.rdbuf(err.rdbuf());
  Outcome outcome;
  outcome.code = parse_command_line(app, static_cast<int>(argv.size()), argv.data());
  std::cout.rdbuf(old_out);
  std::cerr.rdbuf(old_err);
  outcome.out = out.str();
  outcome.err = err.str();
  return outcome;
}

// The help entry of `name`: its line and, when the name column is full and
// the description goes on the next, that one too.
std::string help_entry(const std::string& help, const std::string& name) {
  const auto at = help.find("  " + name + " ");
  if (at == std::string::npos) return {};
  auto end = help.find('\n', at);
  if (help.compare(end + 1, 6, "      ") == 0) end = help.find('\n', end + 1);
  return help.substr(at, end - at + 1);
}

struct Example {
  int rounds = 3;
  double rate = 2.5;
  std::string mode = "fast";
  std::string out;
  std::string scenario;
  std::string url;
  std::vector<std::string> services = {"mapper", "controller"};
  bool quiet = false;
};

void add_example_options(CommandLine& app, Example& e) {
  app.add_option("--rounds", e.rounds, "rounds to run");
  app.add_option("--rate", e.rate, "per second")->check(positive_number());
  app.add_option("--mode", e.mode, "how")->check(CLI::IsMember({"fast", "slow"}));
  app.add_option("--out", e.out, "results folder");
  app.add_option("--scenario", e.scenario, "scenario file")->required();
  app.add_option("--url", e.url, "bus URL (default: $LCM_DEFAULT_URL)");
  app.add_option("--services", e.services, "watched")->delimiter(',');
  app.add_flag("--quiet", e.quiet, "no progress lines");
}

TEST(CommandLine, HelpShowsEveryDefault) {
  CommandLine app("ofn_example", "an example program");
  Example e;
  add_example_options(app, e);
  const Outcome outcome = parse(app, {"--help"});
  ASSERT_EQ(outcome.code, 0);
  EXPECT_EQ(outcome.err, "");
  const std::string& help = outcome.out;
  EXPECT_NE(help.find("an example program"), std::string::npos);
  EXPECT_NE(help.find("Usage: ofn_example"), std::string::npos) << help;
  EXPECT_NE(help_entry(help, "--rounds").find("rounds to run (default: 3)"), std::string::npos)
      << help;
  EXPECT_NE(help_entry(help, "--rate").find("per second (default: 2.5)"), std::string::npos);
  EXPECT_NE(help_entry(help, "--mode").find("how (default: fast)"), std::string::npos);
  EXPECT_NE(help_entry(help, "--out").find("results folder (default: none)"), std::string::npos);
  EXPECT_NE(help_entry(help, "--quiet").find("no progress lines (default: off)"),
            std::string::npos);
  EXPECT_NE(help_entry(help, "--services").find("(default: [mapper,controller])"),
            std::string::npos);
  // Said in words: not repeated.
  EXPECT_NE(help_entry(help, "--url").find("bus URL (default: $LCM_DEFAULT_URL)\n"),
            std::string::npos);
  // A required option has no default: its type column says REQUIRED.
  const std::string scenario = help_entry(help, "--scenario");
  EXPECT_NE(scenario.find("REQUIRED"), std::string::npos);
  EXPECT_EQ(scenario.find("(default"), std::string::npos);
  // CLI11's own "=VALUE" after the type is gone.
  EXPECT_EQ(help.find("=3"), std::string::npos);
  EXPECT_EQ(help_entry(help, "--help").find("(default"), std::string::npos);
  EXPECT_EQ(help_entry(help, "--version").find("(default"), std::string::npos);
}

TEST(CommandLine, VersionIsTheProjectVersion) {
  EXPECT_EQ(version().rfind(OFN_PROJECT_VERSION, 0), 0u) << version();
  CommandLine app("ofn_example", "an example program");
  Example e;
  add_example_options(app, e);
  // --version needs none of the required options.
  const Outcome outcome = parse(app, {"--version"});
  EXPECT_EQ(outcome.code, 0);
  EXPECT_EQ(outcome.out, "ofn_example " + version() + "\n");
  EXPECT_EQ(outcome.err, "");
}

TEST(CommandLine, AGoodCommandLineGoesOn) {
  CommandLine app("ofn_example", "an example program");
  Example e;
  add_example_options(app, e);
  const Outcome outcome = parse(app, {"--scenario", "s.yaml", "--rate", "0.5", "--quiet"});
  EXPECT_FALSE(outcome.code.has_value());
  EXPECT_EQ(outcome.out + outcome.err, "");
  EXPECT_EQ(e.scenario, "s.yaml");
  EXPECT_DOUBLE_EQ(e.rate, 0.5);
  EXPECT_TRUE(e.quiet);
  EXPECT_EQ(e.rounds, 3);
}

TEST(CommandLine, AUsageErrorIsOneLineAndExitCodeTwo) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--scenario", "s.yaml", "--no-such-option"}, "--no-such-option"},
      {{}, "--scenario is required"},
      {{"--scenario"}, "--scenario"},
      {{"--scenario", "s.yaml", "--rounds", "many"}, "--rounds"},
      {{"--scenario", "s.yaml", "--mode", "medium"}, "--mode"},
      {{"--scenario", "s.yaml", "--rate", "abc"}, "--rate: expected a number > 0, got 'abc'"},
      {{"--rate", "abc", "--bogus"}, "not expected: --bogus"},
  };
  for (const auto& [args, fragment] : cases) {
    CommandLine app("ofn_example", "an example program");
    Example e;
    add_example_options(app, e);
    const Outcome outcome = parse(app, args);
    SCOPED_TRACE(fragment);
    EXPECT_EQ(outcome.code, kExitInputError);
    EXPECT_EQ(outcome.out, "");
    EXPECT_EQ(outcome.err.rfind("ofn_example: error: ", 0), 0u) << outcome.err;
    EXPECT_NE(outcome.err.find(fragment), std::string::npos) << outcome.err;
    ASSERT_FALSE(outcome.err.empty());
    EXPECT_EQ(outcome.err.find('\n'), outcome.err.size() - 1) << outcome.err;
    EXPECT_NE(outcome.err.find(" (see --help)\n"), std::string::npos) << outcome.err;
  }
}

TEST(CommandLine, AMisspeltOptionIsNamedNotTheRequiredOneItLeavesOut) {
  CommandLine app("ofn_example", "an example program");
  Example e;
  add_example_options(app, e);
  const Outcome outcome = parse(app, {"--scenaro", "s.yaml"});
  EXPECT_EQ(outcome.code, kExitInputError);
  EXPECT_EQ(outcome.err.rfind("ofn_example: error: The following arguments were not expected: ", 0),
            0u)
      << outcome.err;
  EXPECT_NE(outcome.err.find("--scenaro"), std::string::npos) << outcome.err;
  EXPECT_EQ(outcome.err.find("required"), std::string::npos) << outcome.err;
}

TEST(CommandLine, AMultiLineMessageIsJoined) {
  EXPECT_EQ(usage_error_line("ofn_x", "first\nsecond\n"),
            "ofn_x: error: first second (see --help)");
}

// Runs a validator on one value: its complaint, empty when accepted.
std::string check(const CLI::Validator& validator, std::string value) {
  return validator(value);
}

TEST(CommandLine, NumberChecksSayTheirBound) {
  EXPECT_EQ(check(positive_number(), "0.5"), "");
  EXPECT_EQ(check(positive_number(), "0"), "expected a number > 0, got '0'");
  EXPECT_EQ(check(positive_number(), "abc"), "expected a number > 0, got 'abc'");
  EXPECT_NE(check(positive_number(), "inf"), "");
  EXPECT_NE(check(positive_number(), "nan"), "");
  EXPECT_EQ(check(non_negative_number(), "0"), "");
  EXPECT_EQ(check(non_negative_number(), "-1"), "expected a number >= 0, got '-1'");
  EXPECT_EQ(check(number_between(0.01, 1000.0), "1000"), "");
  EXPECT_EQ(check(number_between(0.01, 1000.0), "0.001"),
            "expected a number in [0.01, 1000], got '0.001'");
  EXPECT_EQ(number_between(0.0, 0.99).get_description(), "[0, 0.99]");
}

}  // namespace
}  // namespace ofn
