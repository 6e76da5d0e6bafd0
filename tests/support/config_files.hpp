#pragma once
// A fixture for tests of config and scenario files: a folder of its own
// per test (ctest runs the tests in parallel processes), files written
// into it, the ConfigError a scenario gives, and EXPECT_NAMES, which
// checks that an error names the file and the field.

#include <gtest/gtest.h>

#include <unistd.h>

#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include "ofn/common/config.hpp"
#include "ofn/common/scenario.hpp"

namespace ofn::testing_support {

namespace fs = std::filesystem;

class ConfigFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("ofn_config_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }
  /// Text of the ConfigError that loading `path` as a scenario throws.
  static std::string scenario_error(const std::string& path) {
    try {
      load_scenario(path);
    } catch (const ConfigError& e) {
      return e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not a ConfigError: " << e.what();
      return "";
    }
    ADD_FAILURE() << path << " loaded without error";
    return "";
  }
  static std::string replace(std::string text, const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
  }

  fs::path dir_;
};

#define EXPECT_NAMES(message, path, field)              \
  do {                                                  \
    const std::string m_ = (message);                   \
    EXPECT_NE(m_.find(path), std::string::npos) << m_;  \
    EXPECT_NE(m_.find(field), std::string::npos) << m_; \
  } while (0)

}  // namespace ofn::testing_support
