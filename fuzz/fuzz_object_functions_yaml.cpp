// Object-function Atlas YAML (indoor_manip object_functions.hpp, yaml-cpp): the manipulation
// plugin's knowledge of which objects perform which actions. A parsed Atlas must explain every
// action the plugin reports, with functions that name an object and a known plane.
#include <string>

#include "harness.hpp"
#include "romo/indoor_manip/action_label.hpp"
#include "romo/indoor_manip/object_functions.hpp"

using romo::fuzz::ExpectOnlyRomoError;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  ExpectOnlyRomoError([&] {
    const auto atlas = romo::indoor_manip::ObjectFunctionAtlas::Parse(text, "fuzz");
    ROMO_DEMAND(!atlas.objects().empty());
    for (const std::string& action : romo::indoor_manip::ActionNames()) {
      for (const auto& f : atlas.FunctionsFor(action)) {
        ROMO_DEMAND(!f.object.empty() && f.label == action);
        ROMO_DEMAND(f.interaction_plane == "vertical" || f.interaction_plane == "table");
      }
      ROMO_DEMAND(!atlas.FunctionsFor(action).empty());
    }
  });
  return 0;
}
