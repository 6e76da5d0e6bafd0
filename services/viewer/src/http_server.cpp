#include "ofn/viewer/http_server.hpp"

#include <httplib.h>

#include <filesystem>
#include <stdexcept>

namespace ofn::viewer {
namespace {

// Streams at most this many page connections at once; each holds a thread.
constexpr size_t kHttpThreads = 16;
// A stream with nothing new sends a comment this often, which also finds
// out when the page has gone.
constexpr std::chrono::milliseconds kKeepAlive{1000};

}  // namespace

std::string default_web_root() {
  std::error_code error;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) return "viewer_web";
  return (exe.parent_path() / "viewer_web").string();
}

HttpServer::HttpServer(SnapshotHub& hub, const std::string& web_root)
    : hub_(hub), server_(std::make_unique<httplib::Server>()) {
  if (!std::filesystem::is_regular_file(std::filesystem::path(web_root) / "index.html"))
    throw std::invalid_argument("web root '" + web_root + "' holds no index.html");
  server_->new_task_queue = [] { return new httplib::ThreadPool(kHttpThreads); };
  if (!server_->set_mount_point("/", web_root))
    throw std::invalid_argument("web root '" + web_root + "' is not a readable directory");
  server_->Get("/api/snapshot", [this](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_content(hub_.current().second, "application/json");
  });
  server_->Get("/api/stream", [this](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    auto seen = std::make_shared<uint64_t>(0);
    res.set_chunked_content_provider(
        "text/event-stream", [this, seen](size_t, httplib::DataSink& sink) {
          if (hub_.closed()) {
            sink.done();
            return true;
          }
          std::string snapshot;
          const uint64_t reached = hub_.wait_newer(*seen, kKeepAlive, snapshot);
          if (reached == *seen) {
            const std::string comment = ": waiting\n\n";
            return sink.write(comment.data(), comment.size());
          }
          *seen = reached;
          const std::string event = "data: " + snapshot + "\n\n";
          return sink.write(event.data(), event.size());
        });
  });
}

HttpServer::~HttpServer() {
  stop();
}

void HttpServer::bind(const std::string& address, int port) {
  if (port == 0) {
    port_ = server_->bind_to_any_port(address);
    if (port_ < 0) throw std::runtime_error("cannot bind HTTP to " + address);
  } else {
    if (!server_->bind_to_port(address, port))
      throw std::runtime_error("cannot bind HTTP to " + address + ":" + std::to_string(port) +
                               " (in use? try another --port)");
    port_ = port;
  }
}

void HttpServer::start() {
  thread_ = std::thread([this] {
    server_->listen_after_bind();
    listen_ended_ = true;
  });
  // stop() only ends a server that is already listening: wait until it is,
  // so that a stop right after the start (an error on the way up) is not
  // lost and the join does not hang.
  while (!server_->is_running() && !listen_ended_)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

void HttpServer::stop() {
  hub_.close();
  if (server_) server_->stop();
  if (thread_.joinable()) thread_.join();
}

}  // namespace ofn::viewer
