#pragma once
// The viewer's HTTP side (cpp-httplib): the page and its script from the
// web root, the newest snapshot as JSON, and a Server-Sent Events stream of
// snapshots. Runs its own threads; the bus thread only touches the hub.

#include <atomic>
#include <memory>
#include <string>
#include <thread>

#include "ofn/viewer/snapshot_hub.hpp"

namespace httplib {
class Server;
}

namespace ofn::viewer {

class HttpServer {
 public:
  /// Serves `web_root` at "/" (it must hold index.html), /api/snapshot and
  /// /api/stream from `hub`.
  HttpServer(SnapshotHub& hub, const std::string& web_root);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  /// Binds the listening socket (in the calling thread's network
  /// namespace; accepted connections stay in it). Port 0 picks a free
  /// port. Throws std::runtime_error when the address cannot be bound.
  void bind(const std::string& address, int port);
  int port() const { return port_; }
  /// Accepts connections on a thread of its own until stop().
  void start();
  /// Ends the streams and the accept loop; joins the threads.
  void stop();

 private:
  SnapshotHub& hub_;
  std::unique_ptr<httplib::Server> server_;
  std::thread thread_;
  std::atomic<bool> listen_ended_{false};
  int port_ = -1;
};

/// "viewer_web" beside the running executable: where the build puts the page.
std::string default_web_root();

}  // namespace ofn::viewer
