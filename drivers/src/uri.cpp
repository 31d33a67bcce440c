#include "romo/drivers/uri.hpp"

#include <cerrno>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "romo/core/check.hpp"

namespace romo::drivers {

Uri Uri::Parse(const std::string& text) {
  const auto sep = text.find("://");
  if (sep == std::string::npos || sep == 0) {
    Fail("malformed source URI '" + text + "': expected scheme://path (e.g. log://run.lcmlog)");
  }
  Uri uri;
  uri.scheme = text.substr(0, sep);
  for (char c : uri.scheme) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '+' || c == '.')) {
      Fail("malformed source URI '" + text + "': bad character in scheme '" + uri.scheme + "'");
    }
  }
  std::string rest = text.substr(sep + 3);
  const auto q = rest.find('?');
  uri.path = rest.substr(0, q);
  if (q != std::string::npos) {
    std::string query = rest.substr(q + 1);
    std::size_t start = 0;
    while (start <= query.size()) {
      const auto amp = query.find('&', start);
      const std::string item =
          query.substr(start, amp == std::string::npos ? std::string::npos : amp - start);
      const auto eq = item.find('=');
      if (item.empty() || eq == std::string::npos || eq == 0) {
        Fail("malformed source URI '" + text + "': query item '" + item +
             "' is not key=value");
      }
      const std::string key = item.substr(0, eq);
      if (uri.query.count(key) != 0) {
        Fail("malformed source URI '" + text + "': query key '" + key + "' given twice");
      }
      uri.query[key] = item.substr(eq + 1);
      if (amp == std::string::npos) break;
      start = amp + 1;
    }
  }
  return uri;
}

std::string Uri::ToString() const {
  std::string s = scheme + "://" + path;
  char sep = '?';
  for (const auto& [k, v] : query) {
    s += sep + k + "=" + v;
    sep = '&';
  }
  return s;
}

std::optional<std::string> Uri::Get(const std::string& key) const {
  const auto it = query.find(key);
  if (it == query.end()) return std::nullopt;
  return it->second;
}

namespace {

// "source URI sim://parking: 'frames=abc' " + @p what.
[[noreturn]] void BadValue(const Uri& uri, const std::string& key, const std::string& value, const std::string& what) {
  Fail("source URI " + uri.scheme + "://" + uri.path + ": '" + key + "=" + value + "' " + what);
}

}  // namespace

std::optional<long long> Uri::GetInt(const std::string& key, long long min, long long max) const {
  const auto v = Get(key);
  if (!v) return std::nullopt;
  errno = 0;
  char* end = nullptr;
  const long long value = std::strtoll(v->c_str(), &end, 10);
  if (v->empty() || *end != '\0' || errno == ERANGE) BadValue(*this, key, *v, "is not an integer");
  if (value < min || value > max) BadValue(*this, key, *v, "is outside " + std::to_string(min) + ".." + std::to_string(max));
  return value;
}

std::optional<int> Uri::GetInt32(const std::string& key) const {
  const auto v = GetInt(key, std::numeric_limits<int>::min(), std::numeric_limits<int>::max());
  if (!v) return std::nullopt;
  return static_cast<int>(*v);
}

std::optional<double> Uri::GetDouble(const std::string& key, double min, double max) const {
  const auto v = Get(key);
  if (!v) return std::nullopt;
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(v->c_str(), &end);
  if (v->empty() || *end != '\0' || errno == ERANGE) BadValue(*this, key, *v, "is not a number");
  if (!std::isfinite(value)) BadValue(*this, key, *v, "is not a finite number");
  if (value < min || value > max) {
    std::ostringstream range;
    range << "is outside " << min << ".." << max;
    BadValue(*this, key, *v, range.str());
  }
  return value;
}

}  // namespace romo::drivers
