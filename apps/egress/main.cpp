// egress: command line of the HSR evacuation-assistance system.

#include <cstdio>
#include <exception>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "commands.h"
#include "egress/ros2/asan_options.h"  // the program links Fast DDS

int main(int argc, char** argv) {
  CLI::App app{
      "egress: an HSR robot brain that opens ADA doors ahead of evacuees, yields to people and "
      "fetches rescue equipment, run against a Bullet digital twin or the real robot.",
      "egress"};
  app.require_subcommand(0, 1);
  app.set_version_flag("-V,--version", egress::apps::VersionText,
                       "Print the egress version and the library versions it was built with");

  egress::apps::AddModelCommand(app);
  egress::apps::AddBtCommand(app);
  egress::apps::AddCostmapCommand(app);
  egress::apps::AddPlanCommand(app);
  egress::apps::AddBenchCommand(app);
  egress::apps::AddSimCommand(app);
  egress::apps::AddEvacCommand(app);
  egress::apps::AddRos2Commands(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const egress::apps::CommandFailed& e) {
    if (*e.what() != '\0') std::fprintf(stderr, "egress: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "egress: error: %s\n", e.what());
    return 1;
  }
  if (argc == 1) {
    std::fputs(app.help().c_str(), stdout);
  }
  return 0;
}
