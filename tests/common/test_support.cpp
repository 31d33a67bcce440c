#include "test_support.hpp"

#include "romo/core/check.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

namespace fs = std::filesystem;

namespace romo::test {
namespace {
std::string Env(const char* name, const std::string& fallback) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' ? std::string(v) : fallback;
}
}  // namespace

std::string SharedData(const std::string& relative) {
  return Env("ROMO_SHARED_DATA", ROMO_DEFAULT_SHARED_DATA) + "/" + relative;
}

bool HaveSharedData(const std::string& relative) {
  const std::string p = SharedData(relative);
  if (fs::exists(p)) return true;
  std::fprintf(stderr, "\n*** SHARED TEST DATA MISSING: %s (set ROMO_SHARED_DATA) ***\n\n", p.c_str());
  return false;
}

std::string SourcePath(const std::string& relative) {
  return Env("ROMO_SOURCE_DIR", ROMO_DEFAULT_SOURCE_DIR) + "/" + relative;
}

ScratchDir::ScratchDir() {
  std::random_device rd;
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = info != nullptr ? std::string(info->test_suite_name()) + "." + info->name()
                                     : std::string("romo");
  for (auto& c : name) {
    if (c == '/') c = '_';
  }
  path_ = (fs::temp_directory_path() /
           ("romo-test-" + name + "-" + std::to_string(getpid()) + "-" + std::to_string(rd())))
              .string();
  fs::create_directories(path_);
}

ScratchDir::~ScratchDir() {
  if (std::getenv("ROMO_KEEP_SCRATCH") == nullptr) {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
}

CommandResult RunShell(const std::string& command_line) {
  ScratchDir tmp;
  const std::string out_path = tmp / "stdout";
  const std::string err_path = tmp / "stderr";
  const std::string full = command_line + " >" + out_path + " 2>" + err_path;
  const int status = std::system(full.c_str());
  CommandResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  result.out = ReadFile(out_path);
  result.err = ReadFile(err_path);
  return result;
}

std::string RomoBinary() { return Env("ROMO_BINARY", ROMO_DEFAULT_BINARY); }

CommandResult RunRomo(const std::string& args) {
  return RunShell("'" + RomoBinary() + "' " + args);
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const romo::Error& e) {
    return e.what();
  }
  return "no error";
}

void WriteFile(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error("cannot write " + path);
  f << text;
}

std::string ReadFile(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

}  // namespace romo::test
