#pragma once
/// The one JSON string escaper every command's --json output uses.
#include <string>

namespace romo {

/// @p text with '"', '\\' and control characters escaped (no surrounding quotes).
std::string JsonEscape(const std::string& text);
/// @p text escaped and quoted: a complete JSON string value.
inline std::string JsonString(const std::string& text) { return "\"" + JsonEscape(text) + "\""; }

}  // namespace romo
