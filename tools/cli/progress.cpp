#include "cli/progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace romo::tools {

Progress::Progress(std::string label, std::uint64_t total)
    : label_(std::move(label)),
      total_(total),
      is_tty_(isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_ - std::chrono::seconds(1)) {}

Progress::~Progress() {
  if (!finished_) Finish();
}

void Progress::Update(std::uint64_t done, const std::string& note) {
  done_ = done;
  const auto now = std::chrono::steady_clock::now();
  // Not a terminal (CI logs): a line every 2 s keeps logs short but shows the work moving.
  const auto period = is_tty_ ? std::chrono::milliseconds(100) : std::chrono::milliseconds(2000);
  if (now - last_draw_ < period && done != total_) return;
  last_draw_ = now;
  Draw(note);
}

void Progress::Finish(const std::string& note) {
  if (finished_) return;
  finished_ = true;
  Draw(note);
  if (is_tty_) std::fputc('\n', stderr);
  std::fflush(stderr);
}

void Progress::Draw(const std::string& note) {
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double rate = elapsed_s > 0 ? done_ / elapsed_s : 0.0;
  char line[256];
  if (total_ > 0) {
    constexpr int kWidth = 30;
    const double fraction = static_cast<double>(done_) / static_cast<double>(total_);
    const int filled = static_cast<int>(fraction * kWidth + 0.5);
    std::string bar(static_cast<std::size_t>(filled > kWidth ? kWidth : filled), '#');
    bar.resize(kWidth, '.');
    const double eta_s = rate > 0 ? (total_ - done_) / rate : 0.0;
    std::snprintf(line, sizeof line, "%s [%s] %llu/%llu %5.1f%% %.1f/s eta %.0fs", label_.c_str(),
                  bar.c_str(), static_cast<unsigned long long>(done_),
                  static_cast<unsigned long long>(total_), 100.0 * fraction, rate, eta_s);
  } else {
    std::snprintf(line, sizeof line, "%s %llu done %.1f/s", label_.c_str(),
                  static_cast<unsigned long long>(done_), rate);
  }
  if (is_tty_) {
    std::fprintf(stderr, "\r\033[K%s %s", line, note.c_str());
  } else {
    std::fprintf(stderr, "%s %s\n", line, note.c_str());
  }
  std::fflush(stderr);
}

}  // namespace romo::tools
