#pragma once
/// Whole-file reads for the YAML loaders (Atlas, object functions, rig configuration).
#include <string>

namespace romo {

/// The bytes of @p path. @throws romo::Error with @p error_if_unreadable when it cannot be opened.
std::string ReadWholeFile(const std::string& path, const std::string& error_if_unreadable);

}  // namespace romo
