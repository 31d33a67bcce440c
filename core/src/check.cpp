#include "romo/core/check.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace romo {

void Fail(const std::string& message) { throw Error(message); }

void FieldCheck::Fail(const char* field, double value, const char* rule) const {
  std::ostringstream msg;
  msg << owner_ << "." << field << " = " << value << ": " << rule;
  romo::Fail(msg.str());
}

void FieldCheck::Positive(const char* field, double value) const {
  if (!(std::isfinite(value) && value > 0)) Fail(field, value, "must be finite and > 0");
}

void FieldCheck::NonNegative(const char* field, double value) const {
  if (!(std::isfinite(value) && value >= 0)) Fail(field, value, "must be finite and >= 0");
}

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
