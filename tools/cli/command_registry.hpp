#pragma once
/// Each `romo` subcommand lives in its own tools/cmd_*.cpp and registers itself with
/// ROMO_REGISTER_COMMAND, so commands can be added without touching main.cpp.
#include <functional>
#include <string>

#include <CLI/CLI.hpp>

namespace romo::tools {

using CommandRegistrar = std::function<void(CLI::App& root)>;

/// Returns true so it can initialise a static in the registering file.
bool RegisterCommand(CommandRegistrar registrar);
/// Calls every registrar on @p root.
void AddRegisteredCommands(CLI::App& root);

/// The subcommand group @p name of @p root ("bench", "eval"), created on first use.
CLI::App& CommandGroup(CLI::App& root, const std::string& name, const std::string& description);

/// Exit code for bad input (a clear message was printed).
inline constexpr int kExitBadInput = 2;
/// Exit code for a run-time failure (camera gone, disk full).
inline constexpr int kExitRuntimeFailure = 3;

}  // namespace romo::tools

#define ROMO_CONCAT_INNER(a, b) a##b
#define ROMO_CONCAT(a, b) ROMO_CONCAT_INNER(a, b)
#define ROMO_REGISTER_COMMAND(registrar) \
  static const bool ROMO_CONCAT(romo_command_registered_, __LINE__) = \
      ::romo::tools::RegisterCommand(registrar)
