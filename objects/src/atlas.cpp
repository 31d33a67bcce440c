#include "romo/objects/atlas.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "romo/core/check.hpp"
#include "romo/core/text_file.hpp"

#ifndef ROMO_DEFAULT_ATLAS
#define ROMO_DEFAULT_ATLAS "config/atlas.yaml"
#endif

namespace romo::objects {
namespace {

[[noreturn]] void Bad(const std::string& source, const std::string& field, const std::string& value,
                      const std::string& why) {
  Fail("atlas '" + source + "': field '" + field + "' = '" + value + "': " + why);
}

std::string Text(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "<missing>";
  if (node.IsScalar()) return node.Scalar();
  YAML::Emitter e;
  e << YAML::Flow << node;
  return e.c_str();
}

double Number(const YAML::Node& parent, const std::string& key, const std::string& field,
              const std::string& source) {
  const YAML::Node node = parent[key];
  if (!node.IsDefined() || !node.IsScalar()) Bad(source, field, Text(node), "need a number");
  double v = 0.0;
  try {
    v = node.as<double>();
  } catch (const YAML::Exception&) {
    Bad(source, field, Text(node), "not a number");
  }
  if (!std::isfinite(v)) Bad(source, field, Text(node), "not finite");
  return v;
}

bool Flag(const YAML::Node& parent, const std::string& key, bool fallback, const std::string& field,
          const std::string& source) {
  const YAML::Node node = parent[key];
  if (!node.IsDefined()) return fallback;
  try {
    return node.as<bool>();
  } catch (const YAML::Exception&) {
    Bad(source, field, Text(node), "need true or false");
  }
}

SizePrior ReadPrior(const YAML::Node& cls, const std::string& key, const std::string& prefix,
                    const std::string& source) {
  const std::string field = prefix + "." + key;
  const YAML::Node node = cls[key];
  if (!node.IsMap()) Bad(source, field, Text(node), "need {mean, sigma, min, max}");
  SizePrior p;
  p.mean_m = Number(node, "mean", field + ".mean", source);
  p.sigma_m = Number(node, "sigma", field + ".sigma", source);
  p.min_m = Number(node, "min", field + ".min", source);
  p.max_m = Number(node, "max", field + ".max", source);
  if (!(p.sigma_m > 0.0)) Bad(source, field + ".sigma", Text(node["sigma"]), "need > 0");
  if (!(p.min_m >= 0.0)) Bad(source, field + ".min", Text(node["min"]), "need >= 0");
  if (!(p.min_m <= p.mean_m && p.mean_m <= p.max_m)) {
    Bad(source, field + ".mean", Text(node["mean"]), "need min <= mean <= max");
  }
  return p;
}

}  // namespace

std::string Atlas::DefaultPath() {
  const char* env = std::getenv("ROMO_ATLAS");
  return env != nullptr && *env != '\0' ? std::string(env) : std::string(ROMO_DEFAULT_ATLAS);
}

Atlas Atlas::Load(const std::string& path) {
  return Parse(ReadWholeFile(path, "atlas '" + path + "': cannot open file"), path);
}

Atlas Atlas::Parse(const std::string& yaml_text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    Fail("atlas '" + source + "': not valid YAML: " + e.what());
  }
  if (!root.IsMap()) Bad(source, "<root>", Text(root), "need a mapping with 'classes'");
  Atlas atlas;
  // yaml-cpp's accessors throw (e.g. YAML::InvalidNode on some malformed maps); name the file.
  try {
    if (root["min_score"].IsDefined()) {
      atlas.min_score_ = Number(root, "min_score", "min_score", source);
      if (!(atlas.min_score_ > 0.0 && atlas.min_score_ < 1.0)) {
        Bad(source, "min_score", Text(root["min_score"]), "need 0 < min_score < 1");
      }
    }
    const YAML::Node classes = root["classes"];
    if (!classes.IsSequence() || classes.size() == 0) {
      Bad(source, "classes", Text(classes), "need a non-empty list of classes");
    }
    for (std::size_t i = 0; i < classes.size(); ++i) {
      const YAML::Node c = classes[i];
      const std::string prefix = "classes[" + std::to_string(i) + "]";
      if (!c.IsMap()) Bad(source, prefix, Text(c), "need a mapping");
      ObjectClass oc;
      const YAML::Node name = c["name"];
      if (!name.IsScalar() || name.Scalar().empty()) Bad(source, prefix + ".name", Text(name), "need a name");
      oc.name = name.Scalar();
      if (atlas.Find(oc.name) >= 0) Bad(source, prefix + ".name", oc.name, "duplicate class");
      const std::string p = prefix + " (" + oc.name + ")";
      const int priors = (c["length_m"].IsDefined() ? 1 : 0) + (c["width_m"].IsDefined() ? 1 : 0) +
                         (c["height_m"].IsDefined() ? 1 : 0);
      if (priors != 0 && priors != 3) {
        Bad(source, p, Text(c), "give all of length_m, width_m, height_m or none");
      }
      oc.has_priors = priors == 3;
      if (oc.has_priors) {
        oc.length = ReadPrior(c, "length_m", p, source);
        oc.width = ReadPrior(c, "width_m", p, source);
        oc.height = ReadPrior(c, "height_m", p, source);
        if (oc.width.mean_m > oc.length.mean_m) {
          Bad(source, p + ".width_m.mean", Text(c["width_m"]["mean"]),
              "width must not exceed length (length is the longer footprint side)");
        }
      }
      if (c["prior"].IsDefined()) {
        oc.prior = Number(c, "prior", p + ".prior", source);
        if (!(oc.prior > 0.0 && oc.prior <= 1.0)) Bad(source, p + ".prior", Text(c["prior"]), "need 0 < prior <= 1");
      }
      const YAML::Node attr = c["attributes"];
      if (attr.IsDefined()) {
        if (!attr.IsMap()) Bad(source, p + ".attributes", Text(attr), "need a mapping");
        const std::string a = p + ".attributes";
        oc.movable = Flag(attr, "movable", oc.movable, a + ".movable", source);
        oc.predict_path = Flag(attr, "predict_path", oc.predict_path, a + ".predict_path", source);
        if (attr["max_speed_mps"].IsDefined()) {
          oc.max_speed_mps = Number(attr, "max_speed_mps", a + ".max_speed_mps", source);
          if (!(oc.max_speed_mps > 0.0)) Bad(source, a + ".max_speed_mps", Text(attr["max_speed_mps"]), "need > 0");
        }
        if (attr["max_occlusion_s"].IsDefined()) {
          oc.max_occlusion_s = Number(attr, "max_occlusion_s", a + ".max_occlusion_s", source);
          if (!(oc.max_occlusion_s >= 0.0)) {
            Bad(source, a + ".max_occlusion_s", Text(attr["max_occlusion_s"]), "need >= 0");
          }
        }
      }
      atlas.classes_.push_back(oc);
    }
    atlas.unknown_ = atlas.Find("unknown");
    if (atlas.unknown_ < 0) Bad(source, "classes", "", "need a class named 'unknown' (the fallback)");
    if (atlas.classes_[static_cast<std::size_t>(atlas.unknown_)].has_priors) {
      Bad(source, "classes (unknown)", "", "the fallback class 'unknown' must have no size priors");
    }
  } catch (const YAML::Exception& e) {
    Fail("atlas '" + source + "': malformed YAML: " + e.what());
  }
  return atlas;
}

int Atlas::Find(const std::string& name) const {
  for (std::size_t i = 0; i < classes_.size(); ++i) {
    if (classes_[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

int Atlas::Require(const std::string& name) const {
  const int i = Find(name);
  if (i < 0) Fail("atlas: no class named '" + name + "'");
  return i;
}

double Atlas::Score(int class_index, double length_m, double width_m, double height_m) const {
  ROMO_THROW_UNLESS(class_index >= 0 && class_index < static_cast<int>(classes_.size()));
  const ObjectClass& c = classes_[static_cast<std::size_t>(class_index)];
  if (!c.has_priors) return 0.0;
  if (width_m > length_m) std::swap(width_m, length_m);
  if (!c.length.Contains(length_m) || !c.width.Contains(width_m) || !c.height.Contains(height_m)) {
    return 0.0;
  }
  auto z2 = [](const SizePrior& p, double x) {
    const double z = (x - p.mean_m) / p.sigma_m;
    return z * z;
  };
  return std::exp(-0.5 * (z2(c.length, length_m) + z2(c.width, width_m) + z2(c.height, height_m)));
}

Classification Atlas::Classify(double length_m, double width_m, double height_m) const {
  if (!std::isfinite(length_m) || !std::isfinite(width_m) || !std::isfinite(height_m) ||
      length_m < 0.0 || width_m < 0.0 || height_m < 0.0) {
    std::ostringstream m;
    m << "atlas: cannot classify box extents (" << length_m << ", " << width_m << ", " << height_m
      << ") m";
    Fail(m.str());
  }
  Classification best{unknown_, 0.0};
  double best_score = 0.0, best_weighted = 0.0;
  for (std::size_t i = 0; i < classes_.size(); ++i) {
    const double s = Score(static_cast<int>(i), length_m, width_m, height_m);
    if (s * classes_[i].prior > best_weighted) {
      best_weighted = s * classes_[i].prior;
      best_score = s;
      best.class_index = static_cast<int>(i);
    }
  }
  if (best_score < min_score_) return {unknown_, 1.0 - best_score};
  best.score = best_score;
  return best;
}

Classification Atlas::Classify(const Box3& box) const {
  return Classify(box.size.x(), box.size.y(), box.size.z());
}

}  // namespace romo::objects
