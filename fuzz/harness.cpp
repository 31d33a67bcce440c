#include "harness.hpp"

#include <cstdio>
#include <cstdlib>
#include <unistd.h>

namespace romo::fuzz {

ScratchFile::ScratchFile(const char* suffix) {
  const char* dir = std::getenv("TMPDIR");
  path_ = std::string(dir != nullptr && *dir != '\0' ? dir : "/tmp") + "/romo_fuzz_" +
          std::to_string(::getpid()) + suffix;
}

ScratchFile::~ScratchFile() { std::remove(path_.c_str()); }

const std::string& ScratchFile::Write(const std::uint8_t* data, std::size_t size) {
  std::FILE* f = std::fopen(path_.c_str(), "wb");
  ROMO_DEMAND(f != nullptr);
  ROMO_DEMAND(size == 0 || std::fwrite(data, 1, size, f) == size);
  ROMO_DEMAND(std::fclose(f) == 0);
  return path_;
}

}  // namespace romo::fuzz
