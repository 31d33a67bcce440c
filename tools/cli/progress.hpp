#pragma once
/// A one-line progress display on stderr for long work (record, sim, replay).
#include <chrono>
#include <cstdint>
#include <string>

namespace romo::tools {

class Progress {
 public:
  /// @param total 0 when the total is unknown (shows a count and rate only).
  Progress(std::string label, std::uint64_t total);
  ~Progress();
  /// Sets the done count and redraws at most ~10 times a second; @p note is shown after the bar.
  void Update(std::uint64_t done, const std::string& note = "");
  /// Draws the final state and ends the line.
  void Finish(const std::string& note = "");

 private:
  void Draw(const std::string& note);

  std::string label_;
  std::uint64_t total_;
  std::uint64_t done_ = 0;
  bool finished_ = false;
  bool is_tty_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace romo::tools
