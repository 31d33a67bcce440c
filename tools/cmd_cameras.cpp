// `romo cameras`: the GigE Vision cameras Aravis discovers (broadcast on every interface).
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "cli/command_registry.hpp"
#include "romo/core/json.hpp"
#include "romo/drivers/gige.hpp"

namespace romo::tools {
namespace {

void Register(CLI::App& root) {
  auto* command = root.add_subcommand(
      "cameras", "List the GigE Vision cameras Aravis discovers (id, vendor, model, serial, address)");
  auto json = std::make_shared<bool>(false);
  command->add_flag("--json", *json, "Print a JSON list instead of a table");
  command->callback([json] {
    const auto devices = drivers::DiscoverGigeCameras();
    if (*json) {
      std::printf("[");
      for (std::size_t i = 0; i < devices.size(); ++i) {
        const auto& d = devices[i];
        std::printf("%s{\"id\":%s,\"vendor\":%s,\"model\":%s,\"serial\":%s,\"address\":%s,\"protocol\":%s}",
                    i ? "," : "", JsonString(d.id).c_str(), JsonString(d.vendor).c_str(),
                    JsonString(d.model).c_str(), JsonString(d.serial).c_str(),
                    JsonString(d.address).c_str(), JsonString(d.protocol).c_str());
      }
      std::printf("]\n");
      return;
    }
    if (devices.empty()) {
      std::printf("no GigE Vision cameras found\n");
      return;
    }
    std::printf("%-28s %-14s %-14s %-16s %-16s %s\n", "id", "vendor", "model", "serial", "address", "protocol");
    for (const auto& d : devices) {
      std::printf("%-28s %-14s %-14s %-16s %-16s %s\n", d.id.c_str(), d.vendor.c_str(), d.model.c_str(),
                  d.serial.c_str(), d.address.c_str(), d.protocol.c_str());
    }
  });
}

ROMO_REGISTER_COMMAND(Register);

}  // namespace
}  // namespace romo::tools
