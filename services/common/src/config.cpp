#include "ofn/common/config.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace ofn {

YamlReader YamlReader::load_file(const std::string& path) {
  std::ifstream probe(path);
  if (!probe) throw ConfigError(path + ": cannot open file");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::ParserException& e) {
    throw ConfigError(path + ": line " + std::to_string(e.mark.line + 1) +
                      ": not valid YAML: " + e.msg);
  }
  if (root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
  if (!root.IsMap()) throw ConfigError(path + ": expected a mapping of fields at the top level");
  return YamlReader(root, path, "");
}

YamlReader YamlReader::empty(const std::string& source) {
  return YamlReader(YAML::Node(YAML::NodeType::Map), source, "");
}

YamlReader::YamlReader(YAML::Node node, std::string file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {}

std::string YamlReader::field(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

void YamlReader::fail(const std::string& key, const std::string& what) const {
  std::ostringstream s;
  s << file_ << ": field '" << field(key) << "': " << what;
  throw ConfigError(s.str());
}

bool YamlReader::has(const std::string& key) const {
  return node_[key].IsDefined();
}

YAML::Node YamlReader::scalar(const std::string& key) {
  used_.insert(key);
  YAML::Node n = node_[key];
  if (n.IsDefined() && !n.IsNull() && !n.IsScalar()) fail(key, "expected a single value");
  return n;
}

double YamlReader::number(const std::string& key, double fallback) {
  YAML::Node n = scalar(key);
  if (!n.IsDefined() || n.IsNull()) return fallback;
  double v = 0;
  try {
    v = n.as<double>();
  } catch (const YAML::Exception&) {
    fail(key, "expected a number, got '" + n.Scalar() + "'");
  }
  if (!std::isfinite(v)) fail(key, "expected a finite number, got '" + n.Scalar() + "'");
  return v;
}

double YamlReader::number(const std::string& key) {
  if (!has(key)) fail(key, "required number is missing");
  return number(key, 0.0);
}

double YamlReader::number_in(const std::string& key, double fallback, double lo, double hi) {
  const double v = number(key, fallback);
  if (v < lo || v > hi) {
    std::ostringstream s;
    s << "expected a number in [" << lo << ", " << hi << "], got " << v;
    fail(key, s.str());
  }
  return v;
}

int YamlReader::integer(const std::string& key, int fallback) {
  YAML::Node n = scalar(key);
  if (!n.IsDefined() || n.IsNull()) return fallback;
  try {
    return n.as<int>();
  } catch (const YAML::Exception&) {
    fail(key, "expected a whole number, got '" + n.Scalar() + "'");
  }
}

bool YamlReader::boolean(const std::string& key, bool fallback) {
  YAML::Node n = scalar(key);
  if (!n.IsDefined() || n.IsNull()) return fallback;
  try {
    return n.as<bool>();
  } catch (const YAML::Exception&) {
    fail(key, "expected true or false, got '" + n.Scalar() + "'");
  }
}

std::string YamlReader::text(const std::string& key, const std::string& fallback) {
  YAML::Node n = scalar(key);
  if (!n.IsDefined() || n.IsNull()) return fallback;
  return n.Scalar();
}

std::string YamlReader::text(const std::string& key) {
  if (!has(key)) fail(key, "required text is missing");
  return text(key, "");
}

std::vector<double> YamlReader::numbers_in(const std::string& key,
                                           const std::vector<double>& fallback, double lo,
                                           double hi) {
  std::vector<double> v = numbers(key, fallback);
  for (double x : v)
    if (!(x >= lo && x <= hi)) {
      std::ostringstream s;
      s << "expected every number in [" << lo << ", " << hi << "], got " << x;
      fail(key, s.str());
    }
  return v;
}

std::vector<double> YamlReader::numbers(const std::string& key, size_t size) {
  used_.insert(key);
  YAML::Node n = node_[key];
  if (!n.IsDefined() || n.IsNull())
    fail(key, "required list of " + std::to_string(size) + " numbers is missing");
  return numbers(key, std::vector<double>(size, 0.0));
}

std::vector<double> YamlReader::numbers(const std::string& key,
                                        const std::vector<double>& fallback) {
  used_.insert(key);
  YAML::Node n = node_[key];
  if (!n.IsDefined() || n.IsNull()) return fallback;
  const std::string expected = "expected a list of " + std::to_string(fallback.size()) + " numbers";
  if (!n.IsSequence() || n.size() != fallback.size()) fail(key, expected);
  std::vector<double> out;
  for (const auto& item : n) {
    double v = 0;
    try {
      v = item.as<double>();
    } catch (const YAML::Exception&) {
      fail(key, expected + ", got '" + (item.IsScalar() ? item.Scalar() : "a nested value") + "'");
    }
    if (!std::isfinite(v)) fail(key, expected + " (finite)");
    out.push_back(v);
  }
  return out;
}

YamlReader YamlReader::child(const std::string& key) {
  used_.insert(key);
  YAML::Node n = node_[key];
  if (!n.IsDefined() || n.IsNull())
    return YamlReader(YAML::Node(YAML::NodeType::Map), file_, field(key));
  if (!n.IsMap()) fail(key, "expected a mapping of fields");
  return YamlReader(n, file_, field(key));
}

std::vector<YamlReader> YamlReader::children(const std::string& key) {
  used_.insert(key);
  YAML::Node n = node_[key];
  std::vector<YamlReader> out;
  if (!n.IsDefined() || n.IsNull()) return out;
  if (!n.IsSequence()) fail(key, "expected a list");
  for (size_t i = 0; i < n.size(); ++i) {
    const std::string item_path = field(key) + "[" + std::to_string(i) + "]";
    if (!n[i].IsMap()) {
      std::ostringstream s;
      s << file_ << ": field '" << item_path << "': expected a mapping of fields";
      throw ConfigError(s.str());
    }
    out.emplace_back(n[i], file_, item_path);
  }
  return out;
}

void YamlReader::fail_unknown(const std::string& key, const std::vector<std::string>& known) const {
  std::ostringstream s;
  s << file_ << ": unknown field '" << field(key) << "'";
  if (!known.empty()) {
    s << " (known here:";
    for (const auto& k : known) s << " " << k;
    s << ")";
  }
  throw ConfigError(s.str());
}

void YamlReader::finish() const {
  for (const auto& kv : node_) {
    const std::string key = kv.first.Scalar();
    if (!used_.count(key)) fail_unknown(key, {used_.begin(), used_.end()});
  }
}

void YamlReader::expect_only(const std::vector<std::string>& known) const {
  for (const auto& kv : node_) {
    const std::string key = kv.first.Scalar();
    if (std::find(known.begin(), known.end(), key) == known.end()) fail_unknown(key, known);
  }
}

}  // namespace ofn
