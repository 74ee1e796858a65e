#include <fmt/format.h>

#include "commands.h"
#include "egress/behavior/library_versions.h"
#include "egress/bt/groot2_publisher.h"
#include "egress/hsr_interface/version.h"
#include "egress/perception/library_versions.h"
#include "egress/planning/library_versions.h"
#include "egress/twin/library_versions.h"

namespace egress::apps {

std::string VersionText() {
  std::string text = fmt::format("egress {} (git {})\n", Version(), GitRevision());
  const auto add = [&](const char* module, const std::vector<LibraryVersion>& libraries) {
    for (const auto& library : libraries) {
      text += fmt::format("  {:<14} {:<10} {}\n", module, library.name, library.version);
    }
  };
  add("hsr_interface", HsrInterfaceLibraryVersions());
  add("twin", twin::LibraryVersions());
  add("perception", perception::LibraryVersions());
  add("planning", planning::LibraryVersions());
  add("behavior", behavior::LibraryVersions());
  add("behavior", {{"ZeroMQ", bt::ZeroMqVersion()}});  // Groot2 monitoring
  add("apps", {{"protobuf", EGRESS_PROTOBUF_VERSION}, {"gRPC", EGRESS_GRPC_VERSION}});
  text.pop_back();  // CLI11 adds the final newline.
  return text;
}

void AddPlannedCommand(CLI::App& app, const std::string& name, const std::string& description,
                       const std::string& arrives_with) {
  auto* command = app.add_subcommand(name, description + " [not available yet]");
  command->allow_extras();
  command->callback([name, arrives_with] {
    throw std::runtime_error(fmt::format(
        "'egress {}' is not available in this build yet; it arrives with {}.", name, arrives_with));
  });
}

}  // namespace egress::apps
