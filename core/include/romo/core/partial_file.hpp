#pragma once
/// Outputs written as PATH.partial and renamed to PATH when complete (recordings, prediction
/// logs): a PATH.partial found when starting is what a killed writer left, and is kept.
#include <string>

namespace romo {

/// Moves an existing @p path.partial to <stem>.interrupted-<k><ext> (ext = @p path's extension,
/// k the first free number) and returns that path; "" when there is no @p path.partial.
/// @throws romo::Error naming the file when it cannot be moved.
std::string KeepInterruptedPartial(const std::string& path);

}  // namespace romo
