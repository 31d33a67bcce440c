// Atlas YAML (objects/atlas, yaml-cpp). A parsed Atlas must classify any box without failing.
#include <string>

#include "harness.hpp"
#include "romo/objects/atlas.hpp"

using romo::fuzz::ExpectOnlyRomoError;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  ExpectOnlyRomoError([&] {
    const auto atlas = romo::objects::Atlas::Parse(text, "fuzz");
    for (const double scale : {0.0, 0.3, 1.0, 4.5, 1e9}) {
      const auto c = atlas.Classify(scale, 0.5 * scale, 1.7 * scale);
      ROMO_DEMAND(c.class_index >= 0 && c.class_index < static_cast<int>(atlas.classes().size()));
    }
  });
  return 0;
}
