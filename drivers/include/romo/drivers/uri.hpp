#pragma once
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
  /// Integer query value; @throws romo::Error naming key and value when not an integer.
  std::optional<long long> GetInt(const std::string& key) const;
  /// Floating-point query value; @throws romo::Error naming key and value when not a number.
  std::optional<double> GetDouble(const std::string& key) const;
};

}  // namespace romo::drivers
