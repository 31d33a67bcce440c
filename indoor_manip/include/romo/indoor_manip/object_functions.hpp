#pragma once
/// The Atlas of object functions (config/object_functions.yaml, dissertation Sec. 4.1.1): for
/// each object the actions it performs, with the motion and pattern that tell them apart. The
/// plugin uses it to name the objects and functions behind an action label.
#include <string>
#include <vector>

namespace romo::indoor_manip {

struct ObjectFunction {
  std::string object;             ///< e.g. "hammer"
  std::string interaction_plane;  ///< "vertical" or "table"
  std::string label;              ///< an ActionNames() entry
  std::string motion;
  std::string pattern;
};

class ObjectFunctionAtlas {
 public:
  /// Loads and validates a YAML file. Every function's label must be an action the plugin
  /// reports, and every such action needs at least one object function.
  /// @throws romo::Error naming the file, line, field and value on any problem.
  static ObjectFunctionAtlas Load(const std::string& path);
  /// Parses YAML text; @p source names it in error messages.
  static ObjectFunctionAtlas Parse(const std::string& yaml_text, const std::string& source);
  /// config/object_functions.yaml of the source tree, or ROMO_OBJECT_FUNCTIONS when set.
  static std::string DefaultPath();

  /// All functions, in file order.
  const std::vector<ObjectFunction>& functions() const { return functions_; }
  /// Object names, in file order.
  std::vector<std::string> objects() const;
  /// The functions whose label is @p label (empty for an unknown label).
  std::vector<ObjectFunction> FunctionsFor(const std::string& label) const;

 private:
  std::vector<ObjectFunction> functions_;
};

}  // namespace romo::indoor_manip
