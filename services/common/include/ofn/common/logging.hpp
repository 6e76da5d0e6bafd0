#pragma once
#include <memory>
#include <string>

#include <spdlog/spdlog.h>

namespace ofn {

/// A logger named after the service, writing to stderr. Loggers are not put
/// in spdlog's registry, so several services can share one process.
std::shared_ptr<spdlog::logger> make_logger(const std::string& name);

/// Sets the level of every logger made from now on and of existing ones
/// made by make_logger. Throws std::invalid_argument for an unknown level.
void set_log_level(const std::string& level);

}  // namespace ofn
