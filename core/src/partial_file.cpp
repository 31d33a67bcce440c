#include "romo/core/partial_file.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "romo/core/check.hpp"

namespace romo {
namespace {

bool Exists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0;
}

}  // namespace

std::string KeepInterruptedPartial(const std::string& path) {
  const std::string partial = path + ".partial";
  if (!Exists(partial)) return "";
  const std::size_t slash = path.find_last_of('/');
  const std::size_t dot = path.find_last_of('.');
  const bool has_ext = dot != std::string::npos && (slash == std::string::npos || dot > slash + 1);
  const std::string stem = has_ext ? path.substr(0, dot) : path;
  const std::string ext = has_ext ? path.substr(dot) : "";
  for (int k = 1; k <= 1000; ++k) {
    const std::string kept = stem + ".interrupted-" + std::to_string(k) + ext;
    if (Exists(kept)) continue;
    if (std::rename(partial.c_str(), kept.c_str()) != 0) {
      Fail(partial + ": left by an interrupted writer; cannot move it aside to " + kept + ": " + std::strerror(errno));
    }
    return kept;
  }
  Fail(partial + ": left by an interrupted writer, and " + stem + ".interrupted-1..1000" + ext +
       " are all taken: move them away");
}

}  // namespace romo
