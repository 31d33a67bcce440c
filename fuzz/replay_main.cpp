// Replays files through a fuzz target's LLVMFuzzerTestOneInput without libFuzzer, so every build
// (gcc included) runs the checked-in corpus and the regression inputs of past crashes as a test.
// Usage: romo_fuzz_replay_<target> <file or directory>...  (directories: every regular file)
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <sys/resource.h>

#include "harness.hpp"

#if defined(__SANITIZE_ADDRESS__)
#define ROMO_REPLAY_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ROMO_REPLAY_UNDER_ASAN 1
#endif
#endif

namespace fs = std::filesystem;

#ifdef ROMO_REPLAY_UNDER_ASAN
// One allocation above 512 MB aborts, as libFuzzer's -malloc_limit_mb=512 in scripts/fuzz.sh.
extern "C" const char* __asan_default_options() { return "max_allocation_size_mb=512"; }
#endif

int main(int argc, char** argv) {
#ifndef ROMO_REPLAY_UNDER_ASAN
  // Like libFuzzer's -malloc_limit_mb: inputs are a few KB, so a parser that trusts a size field
  // and asks for gigabytes must fail here too (bad_alloc escapes: a crash), not just run slowly.
  // Under ASan (whose shadow memory needs the address space) __asan_default_options does it.
  constexpr rlim_t kDataLimitBytes = rlim_t{1} << 30;  // 1 GiB of heap
  const rlimit data_limit{kDataLimitBytes, kDataLimitBytes};
  setrlimit(RLIMIT_DATA, &data_limit);
#endif
  std::vector<fs::path> inputs;
  for (int i = 1; i < argc; ++i) {
    const fs::path arg = argv[i];
    std::error_code ec;
    if (fs::is_directory(arg, ec)) {
      for (const auto& entry : fs::directory_iterator(arg)) {
        if (entry.is_regular_file() && entry.path().filename().string()[0] != '.') {
          inputs.push_back(entry.path());
        }
      }
    } else if (fs::is_regular_file(arg, ec)) {
      inputs.push_back(arg);
    } else if (!fs::exists(arg, ec)) {
      // A target without regressions yet has no folder; that is not an error.
      std::printf("replay: %s does not exist, skipped\n", argv[i]);
    }
  }
  std::sort(inputs.begin(), inputs.end());
  for (const auto& path : inputs) {
    std::ifstream in(path, std::ios::binary);
    const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                          std::istreambuf_iterator<char>());
    if (!in.good() && !in.eof()) {
      std::fprintf(stderr, "replay: cannot read %s\n", path.c_str());
      return 1;
    }
    std::printf("replay: %s (%zu bytes)\n", path.c_str(), bytes.size());
    std::fflush(stdout);  // so a crash names the input that caused it
    LLVMFuzzerTestOneInput(bytes.data(), bytes.size());
  }
  std::printf("replay: %zu inputs, no crash\n", inputs.size());
  return 0;
}
