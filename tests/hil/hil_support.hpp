#pragma once
// Helpers for the hardware-in-loop tests: background processes (emulated cameras) and waiting.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>

#include "test_support.hpp"

namespace romo::hil {

/// A shell command run in the background (exec'd, so the pid is the command's own); killed with
/// SIGKILL by Kill() or the destructor.
class Background {
 public:
  explicit Background(const std::string& command_line) {
    pid_ = fork();
    if (pid_ == 0) {
      execl("/bin/sh", "sh", "-c", ("exec " + command_line).c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
  }
  ~Background() { Kill(SIGKILL); }
  Background(const Background&) = delete;
  Background& operator=(const Background&) = delete;

  /// Sends @p signal and reaps the process; returns its wait status (-1 when already gone).
  int Kill(int signal) {
    if (pid_ <= 0) return -1;
    kill(pid_, signal);
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    return status;
  }
  /// Waits up to @p timeout_s for the process to end by itself; its wait status, or -1 on
  /// timeout (then it is left running).
  int Wait(double timeout_s) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (pid_ > 0 && std::chrono::steady_clock::now() < deadline) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return status;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return -1;
  }
  bool running() const { return pid_ > 0 && waitpid(pid_, nullptr, WNOHANG) == 0; }
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
};

/// Waits until @p path exists; false after @p timeout_s.
inline bool WaitForFile(const std::string& path, double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < deadline) {
    if (std::filesystem::exists(path)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

using ::romo::test::RomoBinary;

}  // namespace romo::hil
