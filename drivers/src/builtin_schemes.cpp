// The schemes drivers provides itself. Each source's translation unit exposes a factory.
#include <map>

#include "romo/drivers/frame_source.hpp"

namespace romo::drivers {

void RegisterBuiltinSchemes(std::map<std::string, SourceFactory>* factories) {
  // Sources add themselves here as they are implemented: (*factories).emplace("log", ...).
  (void)factories;
}

}  // namespace romo::drivers
