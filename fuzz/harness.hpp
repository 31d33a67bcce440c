#pragma once
// Shared by the fuzz targets (fuzz/fuzz_*.cpp). Each target defines LLVMFuzzerTestOneInput: in the
// -DROMO_FUZZ=ON build libFuzzer drives it, in every build replay_main.cpp feeds it the checked-in
// corpus and regression inputs (ctest fuzz_replay.*).
//
// The oracle: a parser of outside input either succeeds or throws romo::Error naming what was
// wrong. Anything else (another exception type, an abort, a sanitizer report, a huge allocation
// for a small input) is a bug, so only romo::Error is caught here.
#include <cstddef>
#include <cstdint>
#include <string>

#include "romo/core/check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace romo::fuzz {

/// Runs @p parse; romo::Error (the parsers' documented failure) is swallowed, anything else escapes.
template <typename F>
void ExpectOnlyRomoError(F&& parse) {
  try {
    parse();
  } catch (const romo::Error&) {
  }
}

/// A per-process scratch file for parsers that read paths (recordings, PCD, ETH/UCY). Rewritten
/// for every input; removed at exit.
class ScratchFile {
 public:
  /// @p suffix: file extension including the dot (".pcd").
  explicit ScratchFile(const char* suffix);
  ~ScratchFile();
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;
  /// Replaces the file's contents with @p data and returns its path.
  const std::string& Write(const std::uint8_t* data, std::size_t size);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace romo::fuzz
