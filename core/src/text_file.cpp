#include "romo/core/text_file.hpp"

#include <fstream>
#include <sstream>

#include "romo/core/check.hpp"

namespace romo {

std::string ReadWholeFile(const std::string& path, const std::string& error_if_unreadable) {
  std::ifstream in(path, std::ios::binary);
  if (!in) Fail(error_if_unreadable);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace romo
