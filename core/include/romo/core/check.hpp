#pragma once
/// Error handling shared by every module (see CONVENTIONS.md, "three kinds of error"):
/// - a caller's broken precondition throws romo::Error (ROMO_THROW_UNLESS / romo::Fail);
/// - a broken internal invariant aborts (ROMO_DEMAND);
/// - an expected run-time failure is a returned status or std::optional, never an exception.
#include <stdexcept>
#include <string>

namespace romo {

/// Thrown for bad input: the message names what was wrong (file, field, value).
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws romo::Error with @p message.
[[noreturn]] void Fail(const std::string& message);

/// Checks a parameter struct's fields: a failure throws romo::Error "Owner.field = value: rule".
class FieldCheck {
 public:
  explicit FieldCheck(const char* owner) : owner_(owner) {}
  [[noreturn]] void Fail(const char* field, double value, const char* rule) const;
  void Positive(const char* field, double value) const;     ///< finite and > 0
  void NonNegative(const char* field, double value) const;  ///< finite and >= 0

 private:
  const char* owner_;
};

namespace internal {
[[noreturn]] void ThrowUnless(const char* condition, const char* func, const char* file, int line);
[[noreturn]] void Abort(const char* condition, const char* func, const char* file, int line);
}  // namespace internal
}  // namespace romo

#define ROMO_THROW_UNLESS(condition)                                                 \
  do {                                                                               \
    if (!(condition)) ::romo::internal::ThrowUnless(#condition, __func__, __FILE__, __LINE__); \
  } while (false)

#define ROMO_DEMAND(condition)                                                       \
  do {                                                                               \
    if (!(condition)) ::romo::internal::Abort(#condition, __func__, __FILE__, __LINE__); \
  } while (false)
