// The `romo` command: every subcommand registers itself from its own cmd_*.cpp.
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>

#include "cli/command_registry.hpp"
#include "romo/core/check.hpp"

int main(int argc, char** argv) {
  CLI::App app{"romo: camera-only perception for robot vehicles"};
  app.require_subcommand(1);
  romo::tools::AddRegisteredCommands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const romo::Error& e) {
    std::fprintf(stderr, "romo: error: %s\n", e.what());
    return romo::tools::kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "romo: failed: %s\n", e.what());
    return romo::tools::kExitRuntimeFailure;
  }
  return 0;
}
