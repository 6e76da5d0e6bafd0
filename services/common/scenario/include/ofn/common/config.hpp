#pragma once
// YAML configuration and scenario reading with errors that name the file,
// the field and what was expected.

#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace ofn {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads fields of one YAML mapping. Every field read is remembered so that
/// finish() can reject fields nobody asked for (usually typos).
class YamlReader {
 public:
  /// Loads a file; a missing or malformed file throws ConfigError.
  static YamlReader load_file(const std::string& path);
  /// An empty mapping (all defaults), for services started without --config.
  static YamlReader empty(const std::string& source);

  YamlReader(YAML::Node node, std::string file, std::string path);

  bool has(const std::string& key) const;
  /// Optional scalar field: `fallback` when absent.
  double number(const std::string& key, double fallback);
  double number(const std::string& key);  // required
  /// Number in [lo, hi].
  double number_in(const std::string& key, double fallback, double lo, double hi);
  int integer(const std::string& key, int fallback);
  bool boolean(const std::string& key, bool fallback);
  std::string text(const std::string& key, const std::string& fallback);
  std::string text(const std::string& key);  // required
  /// A required or optional list of exactly `size` numbers.
  std::vector<double> numbers(const std::string& key, size_t size);
  std::vector<double> numbers(const std::string& key, const std::vector<double>& fallback);
  /// An optional list as long as `fallback`, each number in [lo, hi].
  std::vector<double> numbers_in(const std::string& key, const std::vector<double>& fallback,
                                 double lo, double hi);

  /// A nested mapping; an absent one reads as empty.
  YamlReader child(const std::string& key);
  /// A list of mappings.
  std::vector<YamlReader> children(const std::string& key);

  /// Throws ConfigError naming any field that was never read.
  void finish() const;
  /// Throws ConfigError naming the first field not in `known`; call it
  /// before reading, so that a misspelt field is named rather than the
  /// required one it was meant to be.
  void expect_only(const std::vector<std::string>& known) const;

  [[noreturn]] void fail(const std::string& key, const std::string& what) const;
  const std::string& file() const { return file_; }
  std::string field(const std::string& key) const;

 private:
  YAML::Node scalar(const std::string& key);
  [[noreturn]] void fail_unknown(const std::string& key,
                                 const std::vector<std::string>& known) const;

  YAML::Node node_;
  std::string file_;
  std::string path_;
  std::set<std::string> used_;
};

}  // namespace ofn
