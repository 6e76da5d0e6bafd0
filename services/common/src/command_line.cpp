#include "ofn/common/command_line.hpp"

#include <cmath>
#include <memory>
#include <sstream>

namespace ofn {
namespace {

// CLI11's formatter with every option's default at the end of its
// description, as the project's Python and shell programs show it,
// instead of CLI11's "=VALUE" after the type.
class DefaultsFormatter : public CLI::Formatter {
 public:
  std::string make_option_opts(const CLI::Option* opt) const override {
    std::ostringstream out;
    if (!opt->get_option_text().empty()) return " " + opt->get_option_text();
    if (opt->get_type_size() != 0) {
      if (!opt->get_type_name().empty()) out << " " << get_label(opt->get_type_name());
      if (opt->get_expected_max() == CLI::detail::expected_max_vector_size)
        out << " ...";
      else if (opt->get_expected_min() > 1)
        out << " x " << opt->get_expected();
      if (opt->get_required()) out << " " << get_label("REQUIRED");
    }
    if (!opt->get_envname().empty())
      out << " (" << get_label("Env") << ":" << opt->get_envname() << ")";
    for (const CLI::Option* other : opt->get_needs()) out << " Needs: " << other->get_name();
    for (const CLI::Option* other : opt->get_excludes()) out << " Excludes: " << other->get_name();
    return out.str();
  }

  std::string make_option_desc(const CLI::Option* opt) const override {
    const std::string& description = opt->get_description();
    // --help and --version do, they have no default; a required option
    // says so in its type column; some descriptions name their default
    // in words ("(default: $LCM_DEFAULT_URL or ...)").
    if (opt->check_lname("help") || opt->check_lname("version") || opt->get_required() ||
        description.find("(default: ") != std::string::npos)
      return description;
    std::string shown = opt->get_default_str();
    // A flag takes no value: unset, it is off.
    if (shown.empty()) shown = opt->get_expected_max() == 0 ? "off" : "none";
    return description + (description.empty() ? "" : " ") + "(default: " + shown + ")";
  }
};

std::string format_number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// A number check: `accepts` judges a finite number; `expected` completes
// "expected a number ..." in the complaint.
CLI::Validator number_check(std::function<bool(double)> accepts, const std::string& expected,
                            const std::string& type_description) {
  return CLI::Validator(
      [accepts, expected](std::string& input) -> std::string {
        double value = 0.0;
        if (CLI::detail::lexical_cast(input, value) && std::isfinite(value) && accepts(value))
          return {};
        return "expected a number " + expected + ", got '" + input + "'";
      },
      type_description);
}

}  // namespace

CommandLine::CommandLine(const std::string& program, const std::string& description)
    : CLI::App(description, program), program_(program) {
  option_defaults()->always_capture_default();
  formatter(std::make_shared<DefaultsFormatter>());
  // Qualified: CLI::App has a version() of its own.
  set_version_flag("--version", program + " " + ofn::version(),
                   "print the program's name and version and exit");
  failure_message([program](const CLI::App*, const CLI::Error& e) {
    return usage_error_line(program, e.what()) + "\n";
  });
}

std::optional<int> parse_command_line(CommandLine& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // An argument nobody takes is named before what it may have caused:
    // `--scenaro x` is a misspelt option, not a missing --scenario.
    const bool unexpected = dynamic_cast<const CLI::ExtrasError*>(&e) != nullptr;
    if (e.get_exit_code() != 0 && !unexpected && !app.remaining().empty()) {
      app.exit(CLI::ExtrasError(app.remaining()));
      return kExitInputError;
    }
    // CLI11's own codes (105, 109, ...) are not the project's.
    return app.exit(e) == 0 ? 0 : kExitInputError;
  }
  return std::nullopt;
}

std::string usage_error_line(const std::string& program, const std::string& what) {
  std::string line = what;
  for (char& c : line)
    if (c == '\n' || c == '\r') c = ' ';
  while (!line.empty() && line.back() == ' ') line.pop_back();
  return program + ": error: " + line + " (see --help)";
}

CLI::Validator positive_number() {
  return number_check([](double v) { return v > 0.0; }, "> 0", "POSITIVE");
}

CLI::Validator non_negative_number() {
  return number_check([](double v) { return v >= 0.0; }, ">= 0", "NONNEGATIVE");
}

CLI::Validator number_between(double low, double high) {
  const std::string range = "[" + format_number(low) + ", " + format_number(high) + "]";
  return number_check([low, high](double v) { return v >= low && v <= high; }, "in " + range,
                      range);
}

}  // namespace ofn
