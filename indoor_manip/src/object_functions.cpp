#include "romo/indoor_manip/object_functions.hpp"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "romo/core/check.hpp"
#include "romo/core/text_file.hpp"
#include "romo/indoor_manip/action_label.hpp"

#ifndef ROMO_DEFAULT_OBJECT_FUNCTIONS
#define ROMO_DEFAULT_OBJECT_FUNCTIONS "config/object_functions.yaml"
#endif

namespace romo::indoor_manip {
namespace {

// YAML aliases repeat a node for free, and every function copies its texts: 3000 objects aliasing
// one with a 20 KB motion (55 KB of YAML) made 180 MB. The Atlas has 7 objects with one-line
// texts; these bounds are far above any real one.
constexpr std::size_t kMaxObjects = 256;
constexpr std::size_t kMaxTextChars = 1000;

std::string Text(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "<missing>";
  if (node.IsScalar()) return node.Scalar();
  YAML::Emitter e;
  e << YAML::Flow << node;
  return e.c_str();
}

// "FILE:LINE: field 'F' = 'V': why" with the line of @p at (1-based), as compilers print it.
[[noreturn]] void Bad(const std::string& source, const YAML::Node& at, const std::string& field,
                      const std::string& value, const std::string& why) {
  std::string where = source;
  if (at.IsDefined() && at.Mark().line >= 0) where += ":" + std::to_string(at.Mark().line + 1);
  Fail("object functions " + where + ": field '" + field + "' = '" + value + "': " + why);
}

std::string RequireText(const YAML::Node& parent, const std::string& key, const std::string& field,
                        const std::string& source) {
  const YAML::Node node = parent[key];
  if (!node.IsDefined() || !node.IsScalar() || node.Scalar().empty()) {
    Bad(source, node.IsDefined() ? node : parent, field, Text(node), "need a non-empty text");
  }
  if (node.Scalar().size() > kMaxTextChars) {
    Bad(source, node, field, node.Scalar().substr(0, 40) + "...",
        std::to_string(node.Scalar().size()) + " characters, more than " +
            std::to_string(kMaxTextChars));
  }
  return node.Scalar();
}

void OnlyKeys(const YAML::Node& map, const std::vector<std::string>& known, const std::string& field,
              const std::string& source) {
  for (const auto& kv : map) {
    const std::string key = kv.first.Scalar();
    if (std::find(known.begin(), known.end(), key) == known.end()) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      Bad(source, kv.first, field + "." + key, Text(kv.second), "unknown key (known: " + list + ")");
    }
  }
}

}  // namespace

std::string ObjectFunctionAtlas::DefaultPath() {
  const char* env = std::getenv("ROMO_OBJECT_FUNCTIONS");
  return env != nullptr && *env != '\0' ? std::string(env) : std::string(ROMO_DEFAULT_OBJECT_FUNCTIONS);
}

ObjectFunctionAtlas ObjectFunctionAtlas::Load(const std::string& path) {
  return Parse(ReadWholeFile(path, "object functions '" + path + "': cannot open file"), path);
}

ObjectFunctionAtlas ObjectFunctionAtlas::Parse(const std::string& yaml_text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    // yaml-cpp's message carries "yaml-cpp: error at line L, column C: ..." (0-based mark + 1).
    Fail("object functions " + source + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
  if (!root.IsMap()) Bad(source, root, "<root>", Text(root), "need a mapping with 'objects'");
  OnlyKeys(root, {"objects"}, "<root>", source);
  const YAML::Node objects = root["objects"];
  if (!objects.IsMap() || objects.size() == 0) {
    Bad(source, objects.IsDefined() ? objects : root, "objects", Text(objects),
        "need a non-empty mapping of object names");
  }
  if (objects.size() > kMaxObjects) {
    Bad(source, objects, "objects", std::to_string(objects.size()) + " objects",
        "more than " + std::to_string(kMaxObjects));
  }
  const auto& actions = ActionNames();
  ObjectFunctionAtlas atlas;
  std::set<std::string> names;
  for (const auto& kv : objects) {
    const std::string name = kv.first.Scalar();
    const std::string field = "objects." + name;
    if (name.empty()) Bad(source, kv.first, "objects", "", "object names must not be empty");
    if (!names.insert(name).second) Bad(source, kv.first, field, name, "duplicate object");
    const YAML::Node obj = kv.second;
    if (!obj.IsMap()) Bad(source, obj, field, Text(obj), "need a mapping with interaction_plane and functions");
    OnlyKeys(obj, {"interaction_plane", "functions"}, field, source);
    const std::string plane = RequireText(obj, "interaction_plane", field + ".interaction_plane", source);
    if (plane != "vertical" && plane != "table") {
      Bad(source, obj["interaction_plane"], field + ".interaction_plane", plane, "need 'vertical' or 'table'");
    }
    const YAML::Node fns = obj["functions"];
    // IsDefined first: a missing key of a const map is an invalid node whose IsSequence() throws
    // YAML::InvalidNode (found by fuzz_object_functions_yaml).
    if (!fns.IsDefined() || !fns.IsSequence() || fns.size() == 0) {
      Bad(source, fns.IsDefined() ? fns : obj, field + ".functions", Text(fns), "need a non-empty list");
    }
    std::set<std::string> labels;
    for (std::size_t i = 0; i < fns.size(); ++i) {
      const YAML::Node f = fns[i];
      const std::string ff = field + ".functions[" + std::to_string(i) + "]";
      if (!f.IsMap()) Bad(source, f, ff, Text(f), "need a mapping with label, motion, pattern");
      OnlyKeys(f, {"label", "motion", "pattern"}, ff, source);
      ObjectFunction of;
      of.object = name;
      of.interaction_plane = plane;
      of.label = RequireText(f, "label", ff + ".label", source);
      if (std::find(actions.begin(), actions.end(), of.label) == actions.end()) {
        std::string list;
        for (const auto& a : actions) list += (list.empty() ? "" : ", ") + a;
        Bad(source, f["label"], ff + ".label", of.label, "not an action romo reports (" + list + ")");
      }
      if (!labels.insert(of.label).second) Bad(source, f["label"], ff + ".label", of.label, "duplicate label for this object");
      of.motion = RequireText(f, "motion", ff + ".motion", source);
      of.pattern = RequireText(f, "pattern", ff + ".pattern", source);
      atlas.functions_.push_back(of);
    }
  }
  // Every label the plugin can report must be explained by some object.
  for (const auto& a : actions) {
    if (atlas.FunctionsFor(a).empty()) {
      Bad(source, objects, "objects", a, "action '" + a + "' has no object function (add one that lists it)");
    }
  }
  return atlas;
}

std::vector<std::string> ObjectFunctionAtlas::objects() const {
  std::vector<std::string> out;
  for (const auto& f : functions_) {
    if (std::find(out.begin(), out.end(), f.object) == out.end()) out.push_back(f.object);
  }
  return out;
}

std::vector<ObjectFunction> ObjectFunctionAtlas::FunctionsFor(const std::string& label) const {
  std::vector<ObjectFunction> out;
  for (const auto& f : functions_) {
    if (f.label == label) out.push_back(f);
  }
  return out;
}

}  // namespace romo::indoor_manip
