// viewer (ground station): the flight live in a browser. Joins the bus,
// aggregates what the page draws and serves the page and a snapshot stream
// over HTTP on the loopback.

#include <fcntl.h>
#include <sched.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>

#include <CLI/CLI.hpp>

#include "ofn/common/logging.hpp"
#include "ofn/common/service_main.hpp"
#include "ofn/viewer/http_server.hpp"
#include "ofn/viewer/viewer_service.hpp"

namespace {

// Moves the calling thread into the network namespace at `path`
// (/proc/PID/ns/net): the bus is joined there while the HTTP socket, bound
// before, stays where the browser can reach it.
void enter_network_namespace(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0)
    throw std::invalid_argument("--lcm-netns: cannot open '" + path + "': " + std::strerror(errno));
  const int result = ::setns(fd, CLONE_NEWNET);
  const int error = errno;
  ::close(fd);
  if (result != 0)
    throw std::runtime_error("--lcm-netns: cannot enter '" + path + "': " + std::strerror(error) +
                             " (needs CAP_SYS_ADMIN, e.g. root)");
}

}  // namespace

int main(int argc, char** argv) {
  ofn::CommandLine app{
      "ofn_viewer", "ofn viewer: the flight live in a browser (top view, altitude, plans, status)"};
  ofn::CommonOptions options;
  ofn::add_common_options(app, options, /*with_clock=*/true, /*with_config=*/false);
  std::string address = "127.0.0.1";
  int port = 8765;
  std::string lcm_netns;
  std::string web_root = ofn::viewer::default_web_root();
  std::string url_file;
  double rate = 10.0;
  ofn::viewer::ViewStateConfig view;
  app.add_option("--http-address", address, "address the page is served on");
  app.add_option("--port", port, "HTTP port (0: any free port)")->check(CLI::Range(0, 65535));
  app.add_option("--lcm-netns", lcm_netns,
                 "join the bus in this network namespace (e.g. /proc/PID/ns/net of a flight in "
                 "deploy/netns.sh) while serving HTTP in the viewer's own; needs root");
  app.add_option("--web-root", web_root, "folder with the page (index.html, viewer.js)");
  app.add_option("--url-file", url_file, "write the page's URL to this file once it is served");
  app.add_option("--rate", rate, "snapshots per second of the clock")
      ->check(ofn::number_between(0.1, 100.0));
  app.add_option("--units", view.display_unit, "length unit the page shows")
      ->check(CLI::IsMember({"ft", "m"}));
  app.add_option("--trail-points", view.trail_max_points, "vehicle trail points kept")
      ->check(CLI::Range(2, 1000000));
  app.add_option("--stale-after", view.stale_after,
                 "s of navigation time after which a layer is shown stale")
      ->check(ofn::positive_number());
  app.add_option("--ref-traj-timeout", view.ref_traj_timeout,
                 "s the controller flies a plan past its stamp before its stop (controller "
                 "ref_traj_timeout)")
      ->check(ofn::non_negative_number());
  app.add_option("--stop-accel-fraction", view.stop_accel_fraction,
                 "deceleration of the plan's stop, share of the acceleration limit (controller "
                 "reference_selector.stop_accel_fraction)")
      ->check(ofn::number_between(0.01, 1.0));
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;

  return ofn::guarded_main("ofn_viewer", [&] {
    ofn::set_log_level(options.log_level);
    ofn::viewer::check(view);
    ofn::viewer::SnapshotHub hub;
    // The page and its readers see the same shape from the first request:
    // an empty view (no vehicle yet) until the bus is joined and the
    // service publishes, never the hub's bare "{}".
    auto empty_view = ofn::viewer::ViewState(view).snapshot();
    empty_view["bus"] = {{"received", 0}, {"rejected", 0}};
    hub.publish(ofn::viewer::ViewState::to_text(empty_view));
    ofn::viewer::HttpServer http(hub, web_root);
    http.bind(address, port);
    http.start();
    const std::string url = "http://" + address + ":" + std::to_string(http.port()) + "/";
    if (!lcm_netns.empty()) enter_network_namespace(lcm_netns);
    auto lcm = ofn::open_lcm(options);
    auto clock = ofn::make_clock(options.clock);
    ofn::viewer::ViewerService service(*lcm, *clock, view, hub, rate);
    service.publish_snapshot();
    service.node().log().info("page at {} (bus {}, clock {})", url,
                              lcm_netns.empty() ? "here" : "in " + lcm_netns, clock->describe());
    if (!url_file.empty()) {
      std::ofstream out(url_file);
      out << url << "\n";
      if (!out) throw std::runtime_error("cannot write --url-file '" + url_file + "'");
    }
    const int code = ofn::run_nodes(*lcm, *clock, {&service.node()});
    http.stop();
    return code;
  });
}
