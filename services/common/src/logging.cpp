#include "ofn/common/logging.hpp"

#include <mutex>
#include <stdexcept>
#include <vector>

#include <spdlog/sinks/stdout_color_sinks.h>

namespace ofn {
namespace {

std::mutex& registry_mutex() {
  static std::mutex m;
  return m;
}
std::vector<std::weak_ptr<spdlog::logger>>& loggers() {
  static std::vector<std::weak_ptr<spdlog::logger>> all;
  return all;
}
spdlog::level::level_enum& current_level() {
  static spdlog::level::level_enum level = spdlog::level::info;
  return level;
}

}  // namespace

std::shared_ptr<spdlog::logger> make_logger(const std::string& name) {
  static auto sink = std::make_shared<spdlog::sinks::stderr_color_sink_mt>();
  auto logger = std::make_shared<spdlog::logger>(name, sink);
  logger->set_pattern("%H:%M:%S.%e %^%-5l%$ [%n] %v");
  std::lock_guard<std::mutex> lock(registry_mutex());
  logger->set_level(current_level());
  loggers().push_back(logger);
  return logger;
}

void set_log_level(const std::string& level) {
  const auto parsed = spdlog::level::from_str(level);
  // from_str answers "off" for anything it does not know.
  if (parsed == spdlog::level::off && level != "off")
    throw std::invalid_argument("unknown log level '" + level +
                                "' (expected trace, debug, info, warn, error, critical or off)");
  std::lock_guard<std::mutex> lock(registry_mutex());
  current_level() = parsed;
  for (auto& weak : loggers())
    if (auto l = weak.lock()) l->set_level(parsed);
}

}  // namespace ofn
