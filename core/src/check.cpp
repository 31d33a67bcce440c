#include "romo/core/check.hpp"

#include <cstdio>
#include <cstdlib>

namespace romo {

void Fail(const std::string& message) { throw Error(message); }

namespace internal {

void ThrowUnless(const char* condition, const char* func, const char* file, int line) {
  throw Error(std::string("precondition failed in ") + func + ": " + condition + " (" + file + ":" +
              std::to_string(line) + ")");
}

void Abort(const char* condition, const char* func, const char* file, int line) {
  std::fprintf(stderr, "romo: internal invariant broken in %s: %s (%s:%d)\n", func, condition, file,
               line);
  std::abort();
}

}  // namespace internal
}  // namespace romo
