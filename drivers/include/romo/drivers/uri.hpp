#pragma once
#include <limits>
#include <map>
#include <optional>
#include <string>

namespace romo::drivers {

/// A source URI "scheme://path?key=value&key=value". Parsing is strict: bad input throws.
struct Uri {
  std::string scheme;
  std::string path;
  std::map<std::string, std::string> query;

  /// @throws romo::Error naming the URI when it has no "scheme://" or a malformed query.
  static Uri Parse(const std::string& text);

  std::string ToString() const;
  /// The query value for @p key, or nullopt.
  std::optional<std::string> Get(const std::string& key) const;
  /// Integer query value in [min, max]; @throws romo::Error naming key and value when not an
  /// integer or outside the range (callers narrowing to int pass int's range, so a value that
  /// would wrap is refused instead of turning into another one).
  std::optional<long long> GetInt(const std::string& key, long long min = std::numeric_limits<long long>::min(),
                                  long long max = std::numeric_limits<long long>::max()) const;
  /// GetInt within int's range.
  std::optional<int> GetInt32(const std::string& key) const;
  /// Finite floating-point query value in [min, max]; nan and inf are refused (no option means
  /// them, and converting them to counts or durations is undefined).
  /// @throws romo::Error naming key and value.
  std::optional<double> GetDouble(const std::string& key, double min = -std::numeric_limits<double>::max(),
                                  double max = std::numeric_limits<double>::max()) const;
};

}  // namespace romo::drivers
