#pragma once
/// Helpers shared by the test suites: external data, scratch folders, running the CLI.
#include <functional>
#include <string>

#include <gtest/gtest.h>

namespace romo::test {

/// Path under the shared external data folder (ROMO_SHARED_DATA, default ../shared/data).
std::string SharedData(const std::string& relative);
/// True when SharedData(relative) exists; otherwise prints a loud notice.
bool HaveSharedData(const std::string& relative);
/// Path under the source tree (ROMO_SOURCE_DIR).
std::string SourcePath(const std::string& relative);
/// A fresh empty folder for this test, removed by the destructor.
class ScratchDir {
 public:
  ScratchDir();
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::string& path() const { return path_; }
  std::string operator/(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

struct CommandResult {
  int exit_code = -1;
  std::string out;  ///< stdout
  std::string err;  ///< stderr
};
/// The `romo` binary under test: ROMO_BINARY when set, else the one built with this tree.
std::string RomoBinary();
/// Runs RomoBinary() with @p args (a shell-quoted string).
CommandResult RunRomo(const std::string& args);
/// Runs an arbitrary shell command line.
CommandResult RunShell(const std::string& command_line);

/// The message of the romo::Error @p f throws, or "no error".
std::string ErrorOf(const std::function<void()>& f);

/// Writes @p text into @p path (overwriting).
void WriteFile(const std::string& path, const std::string& text);
std::string ReadFile(const std::string& path);

}  // namespace romo::test

/// Skips the test loudly when shared data is absent (it is present in CI and on dev machines).
#define ROMO_REQUIRE_SHARED_DATA(relative)                                         \
  do {                                                                             \
    if (!::romo::test::HaveSharedData(relative)) {                                 \
      GTEST_SKIP() << "shared test data missing: " << ::romo::test::SharedData(relative); \
    }                                                                              \
  } while (false)
