#include "cli/command_registry.hpp"

#include <vector>

namespace romo::tools {
namespace {
std::vector<CommandRegistrar>& Registrars() {
  static std::vector<CommandRegistrar> registrars;
  return registrars;
}
}  // namespace

bool RegisterCommand(CommandRegistrar registrar) {
  Registrars().push_back(std::move(registrar));
  return true;
}

void AddRegisteredCommands(CLI::App& root) {
  for (auto& registrar : Registrars()) registrar(root);
}

CLI::App& CommandGroup(CLI::App& root, const std::string& name, const std::string& description) {
  for (CLI::App* sub : root.get_subcommands([](CLI::App*) { return true; })) {
    if (sub->get_name() == name) return *sub;
  }
  CLI::App* group = root.add_subcommand(name, description);
  group->require_subcommand(1);
  return *group;
}

}  // namespace romo::tools
