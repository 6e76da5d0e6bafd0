// mapper (Onboard2): obstacle grid, 3-D occupancy, cuboid obstacle database.

#include <CLI/CLI.hpp>

#include "ofn/common/service_main.hpp"
#include "ofn/mapper/mapper_service.hpp"

int main(int argc, char** argv) {
  ofn::CommandLine app{"ofn_mapper",
                       "ofn mapper: obstacle grid (OBSTACLE_GRID) and cuboid database (CUBOIDS)"};
  ofn::CommonOptions options;
  ofn::add_common_options(app, options);
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;

  return ofn::guarded_main("ofn_mapper", [&] {
    auto reader = options.config.empty() ? ofn::YamlReader::empty("(defaults)")
                                         : ofn::YamlReader::load_file(options.config);
    auto config = ofn::mapping::load_mapper_config(reader);
    auto lcm = ofn::open_lcm(options);
    auto clock = ofn::make_clock(options.clock);
    ofn::mapping::MapperService service(*lcm, *clock, config);
    service.node().log().info("grid {:.0f} m square at {:.2f} m, clock {}",
                              2 * config.mapper.grid.half_extent, config.mapper.grid.resolution,
                              clock->describe());
    return ofn::run_nodes(*lcm, *clock, {&service.node()});
  });
}
