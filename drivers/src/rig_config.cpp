// GigE rig configuration: YAML at the edge, a plain validated struct inside.
#include <arpa/inet.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "romo/core/check.hpp"
#include "romo/core/text_file.hpp"
#include "romo/drivers/gige.hpp"

namespace romo::drivers {
namespace {

namespace fs = std::filesystem;

struct FormatName {
  GigePixelFormat format;
  const char* name;
};
constexpr FormatName kFormatNames[] = {
    {GigePixelFormat::kMono8, "Mono8"},         {GigePixelFormat::kMono12, "Mono12"},
    {GigePixelFormat::kMono16, "Mono16"},       {GigePixelFormat::kRgb8, "RGB8"},
    {GigePixelFormat::kBayerRG8, "BayerRG8"},   {GigePixelFormat::kBayerGR8, "BayerGR8"},
    {GigePixelFormat::kBayerGB8, "BayerGB8"},   {GigePixelFormat::kBayerBG8, "BayerBG8"},
};

std::string KnownFormats() {
  std::string known;
  for (const auto& entry : kFormatNames) known += (known.empty() ? "" : ", ") + std::string(entry.name);
  return known;
}

// Errors name the origin (file), the field path and the offending value.
[[noreturn]] void FieldError(const std::string& origin, const std::string& field,
                             const std::string& value, const std::string& why) {
  Fail(origin + ": field '" + field + "' = '" + value + "': " + why);
}

std::string NodeText(const YAML::Node& node) {
  if (!node) return "<missing>";
  if (node.IsScalar()) return node.Scalar();
  YAML::Emitter out;
  out << YAML::Flow << node;
  return out.c_str();
}

void RejectUnknownKeys(const YAML::Node& map, const std::set<std::string>& known,
                       const std::string& origin, const std::string& where) {
  for (const auto& item : map) {
    // A YAML complex key ("? ...") is a map or list: yaml-cpp's as<string> would throw BadConversion.
    if (!item.first.IsScalar()) {
      FieldError(origin, where.empty() ? "(key)" : where + ".(key)", NodeText(item.first),
                 "a key must be plain text");
    }
    const std::string key = item.first.Scalar();
    if (known.count(key) == 0) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      FieldError(origin, where.empty() ? key : where + "." + key, NodeText(item.second),
                 "unknown field (known: " + list + ")");
    }
  }
}

template <typename T>
T Scalar(const YAML::Node& node, const std::string& origin, const std::string& field,
         const char* expected) {
  if (!node.IsScalar()) FieldError(origin, field, NodeText(node), std::string("expected ") + expected);
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    FieldError(origin, field, node.Scalar(), std::string("expected ") + expected);
  }
}

// Reads an optional scalar into *out; absent keys keep the in-class default.
template <typename T>
void Optional(const YAML::Node& map, const char* key, const std::string& origin,
              const std::string& where, const char* expected, T* out) {
  const YAML::Node node = map[key];
  if (!node) return;
  *out = Scalar<T>(node, origin, where.empty() ? key : where + "." + key, expected);
}

GigeCameraRef ParseCamera(const YAML::Node& node, const std::string& origin,
                          const std::string& field) {
  if (!node) FieldError(origin, field, "<missing>", "required: {serial: ...} or {address: ...}");
  if (!node.IsMap()) FieldError(origin, field, NodeText(node), "expected {serial: ...} or {address: ...}");
  RejectUnknownKeys(node, {"serial", "address"}, origin, field);
  GigeCameraRef ref;
  Optional(node, "serial", origin, field, "a string", &ref.serial);
  Optional(node, "address", origin, field, "an IPv4 address", &ref.address);
  return ref;
}

bool IsIpv4(const std::string& text) {
  in_addr addr{};
  return inet_pton(AF_INET, text.c_str(), &addr) == 1;
}

std::string Fmt(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

void ValidateCamera(const GigeCameraRef& ref, const std::string& origin, const std::string& field) {
  if (ref.serial.empty() == ref.address.empty()) {
    FieldError(origin, field, "serial='" + ref.serial + "' address='" + ref.address + "'",
               "give exactly one of serial and address");
  }
  if (!ref.address.empty() && !IsIpv4(ref.address)) {
    FieldError(origin, field + ".address", ref.address, "not an IPv4 address");
  }
}

}  // namespace

const char* ToString(GigePixelFormat format) {
  for (const auto& entry : kFormatNames) {
    if (entry.format == format) return entry.name;
  }
  return "unknown";
}

std::optional<GigePixelFormat> ParseGigePixelFormat(const std::string& name) {
  for (const auto& entry : kFormatNames) {
    if (name == entry.name) return entry.format;
  }
  return std::nullopt;
}

PixelFormat DeliveredFormat(GigePixelFormat format) {
  switch (format) {
    case GigePixelFormat::kMono8: return PixelFormat::kMono8;
    case GigePixelFormat::kMono12:
    case GigePixelFormat::kMono16: return PixelFormat::kMono16;
    default: return PixelFormat::kRgb8;
  }
}

GigePixelFormat ServedFormat(PixelFormat format) {
  switch (format) {
    case PixelFormat::kMono8: return GigePixelFormat::kMono8;
    case PixelFormat::kMono16: return GigePixelFormat::kMono16;
    case PixelFormat::kRgb8: return GigePixelFormat::kRgb8;
  }
  Fail("unknown pixel format " + std::to_string(static_cast<int>(format)));
}

const char* ToString(TriggerMode mode) {
  return mode == TriggerMode::kSoftware ? "software" : "free-run";
}

std::string GigeCameraRef::Describe() const {
  return address.empty() ? "serial:" + serial : "ip:" + address;
}

GigeConfig GigeConfig::Load(const std::string& path) {
  const std::string text = ReadWholeFile(path, path + ": cannot open rig configuration (missing or unreadable)");
  return FromYaml(text, path, fs::path(path).parent_path().string());
}

GigeConfig GigeConfig::FromYaml(const std::string& yaml_text, const std::string& origin,
                                const std::string& base_dir) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::ParserException& e) {
    Fail(origin + ": not valid YAML at line " + std::to_string(e.mark.line + 1) + ", column " +
         std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
  if (!root.IsMap()) Fail(origin + ": expected a YAML map with a 'rigs' list, got '" + NodeText(root) + "'");
  RejectUnknownKeys(root,
                    {"rigs", "discovery_timeout_s", "lost_timeout_s", "max_backoff_s",
                     "stall_timeout_s", "buffers_per_camera", "packet_socket"},
                    origin, "");
  GigeConfig config;
  Optional(root, "discovery_timeout_s", origin, "", "seconds", &config.discovery_timeout_s);
  Optional(root, "lost_timeout_s", origin, "", "seconds", &config.lost_timeout_s);
  Optional(root, "max_backoff_s", origin, "", "seconds", &config.max_backoff_s);
  Optional(root, "stall_timeout_s", origin, "", "seconds", &config.stall_timeout_s);
  Optional(root, "buffers_per_camera", origin, "", "an integer", &config.buffers_per_camera);
  Optional(root, "packet_socket", origin, "", "true or false", &config.packet_socket);

  const YAML::Node rigs = root["rigs"];
  if (!rigs) FieldError(origin, "rigs", "<missing>", "required: a list of rigs");
  if (!rigs.IsSequence()) FieldError(origin, "rigs", NodeText(rigs), "expected a list of rigs");
  for (std::size_t i = 0; i < rigs.size(); ++i) {
    const YAML::Node node = rigs[i];
    const std::string where = "rigs[" + std::to_string(i) + "]";
    if (!node.IsMap()) FieldError(origin, where, NodeText(node), "expected a map");
    RejectUnknownKeys(node,
                      {"rig_id", "name", "left", "right", "pixel_format", "exposure_us", "gain_db",
                       "frame_rate_hz", "packet_size", "trigger", "pairing_tolerance_ms",
                       "calibration"},
                      origin, where);
    GigeRigConfig rig;
    if (!node["rig_id"]) FieldError(origin, where + ".rig_id", "<missing>", "required");
    rig.rig_id = Scalar<int>(node["rig_id"], origin, where + ".rig_id", "an integer");
    Optional(node, "name", origin, where, "a string", &rig.name);
    rig.left = ParseCamera(node["left"], origin, where + ".left");
    rig.right = ParseCamera(node["right"], origin, where + ".right");
    if (node["pixel_format"]) {
      const auto name = Scalar<std::string>(node["pixel_format"], origin, where + ".pixel_format", "a string");
      const auto format = ParseGigePixelFormat(name);
      if (!format) FieldError(origin, where + ".pixel_format", name, "unknown (known: " + KnownFormats() + ")");
      rig.pixel_format = *format;
    }
    Optional(node, "exposure_us", origin, where, "microseconds", &rig.exposure_us);
    Optional(node, "gain_db", origin, where, "decibels", &rig.gain_db);
    Optional(node, "frame_rate_hz", origin, where, "hertz", &rig.frame_rate_hz);
    Optional(node, "packet_size", origin, where, "bytes (integer)", &rig.packet_size_bytes);
    if (node["trigger"]) {
      const auto name = Scalar<std::string>(node["trigger"], origin, where + ".trigger", "a string");
      if (name == "free-run") {
        rig.trigger = TriggerMode::kFreeRun;
      } else if (name == "software") {
        rig.trigger = TriggerMode::kSoftware;
      } else {
        FieldError(origin, where + ".trigger", name, "unknown (known: free-run, software)");
      }
    }
    Optional(node, "pairing_tolerance_ms", origin, where, "milliseconds", &rig.pairing_tolerance_ms);
    Optional(node, "calibration", origin, where, "a file path", &rig.calibration_path);
    if (!rig.calibration_path.empty() && fs::path(rig.calibration_path).is_relative() &&
        !base_dir.empty()) {
      rig.calibration_path = (fs::path(base_dir) / rig.calibration_path).lexically_normal().string();
    }
    config.rigs.push_back(std::move(rig));
  }
  config.Validate(origin);
  return config;
}

void GigeConfig::Validate(const std::string& origin) const {
  auto positive = [&](double value, const std::string& field, double max) {
    if (!std::isfinite(value) || value <= 0.0 || value > max) {
      FieldError(origin, field, Fmt(value), "must be > 0 and <= " + Fmt(max));
    }
  };
  positive(discovery_timeout_s, "discovery_timeout_s", 600.0);
  positive(lost_timeout_s, "lost_timeout_s", 600.0);
  positive(max_backoff_s, "max_backoff_s", 600.0);
  positive(stall_timeout_s, "stall_timeout_s", 86400.0);
  if (buffers_per_camera < 2 || buffers_per_camera > 256) {
    FieldError(origin, "buffers_per_camera", std::to_string(buffers_per_camera), "must be in [2, 256]");
  }
  if (rigs.empty()) FieldError(origin, "rigs", "[]", "at least one rig is required");
  std::set<int> ids;
  std::set<std::string> cameras;
  for (std::size_t i = 0; i < rigs.size(); ++i) {
    const GigeRigConfig& rig = rigs[i];
    const std::string where = "rigs[" + std::to_string(i) + "]";
    if (rig.rig_id < 0 || rig.rig_id > 255) {
      FieldError(origin, where + ".rig_id", std::to_string(rig.rig_id), "must be in [0, 255]");
    }
    if (!ids.insert(rig.rig_id).second) {
      FieldError(origin, where + ".rig_id", std::to_string(rig.rig_id), "used by an earlier rig");
    }
    ValidateCamera(rig.left, origin, where + ".left");
    ValidateCamera(rig.right, origin, where + ".right");
    for (const auto* side : {&rig.left, &rig.right}) {
      if (!cameras.insert(side->Describe()).second) {
        FieldError(origin, where + (side == &rig.left ? ".left" : ".right"), side->Describe(),
                   "camera already used by another rig or side");
      }
    }
    positive(rig.exposure_us, where + ".exposure_us", 10e6);
    if (!std::isfinite(rig.gain_db) || rig.gain_db < 0.0 || rig.gain_db > 60.0) {
      FieldError(origin, where + ".gain_db", Fmt(rig.gain_db), "must be in [0, 60]");
    }
    positive(rig.frame_rate_hz, where + ".frame_rate_hz", 1000.0);
    if (rig.packet_size_bytes != 0 && (rig.packet_size_bytes < 576 || rig.packet_size_bytes > 65000)) {
      FieldError(origin, where + ".packet_size", std::to_string(rig.packet_size_bytes),
                 "must be 0 (negotiate) or in [576, 65000] bytes");
    }
    // A tolerance of half a frame period or more could pair frames of different instants.
    const double half_period_ms = 500.0 / rig.frame_rate_hz;
    if (!std::isfinite(rig.pairing_tolerance_ms) || rig.pairing_tolerance_ms < 0.0 ||
        rig.pairing_tolerance_ms >= half_period_ms) {
      FieldError(origin, where + ".pairing_tolerance_ms", Fmt(rig.pairing_tolerance_ms),
                 "must be >= 0 and below half the frame period (" + Fmt(half_period_ms) + " ms)");
    }
  }
}

std::string GigeConfig::ToYaml() const {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "discovery_timeout_s" << YAML::Value << discovery_timeout_s;
  out << YAML::Key << "lost_timeout_s" << YAML::Value << lost_timeout_s;
  out << YAML::Key << "max_backoff_s" << YAML::Value << max_backoff_s;
  out << YAML::Key << "stall_timeout_s" << YAML::Value << stall_timeout_s;
  out << YAML::Key << "buffers_per_camera" << YAML::Value << buffers_per_camera;
  out << YAML::Key << "packet_socket" << YAML::Value << packet_socket;
  out << YAML::Key << "rigs" << YAML::Value << YAML::BeginSeq;
  auto camera = [&](const char* key, const GigeCameraRef& ref) {
    out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginMap;
    if (ref.address.empty()) {
      out << YAML::Key << "serial" << YAML::Value << ref.serial;
    } else {
      out << YAML::Key << "address" << YAML::Value << ref.address;
    }
    out << YAML::EndMap;
  };
  for (const GigeRigConfig& rig : rigs) {
    out << YAML::BeginMap;
    out << YAML::Key << "rig_id" << YAML::Value << rig.rig_id;
    if (!rig.name.empty()) out << YAML::Key << "name" << YAML::Value << rig.name;
    camera("left", rig.left);
    camera("right", rig.right);
    out << YAML::Key << "pixel_format" << YAML::Value << ToString(rig.pixel_format);
    out << YAML::Key << "exposure_us" << YAML::Value << rig.exposure_us;
    out << YAML::Key << "gain_db" << YAML::Value << rig.gain_db;
    out << YAML::Key << "frame_rate_hz" << YAML::Value << rig.frame_rate_hz;
    out << YAML::Key << "packet_size" << YAML::Value << rig.packet_size_bytes;
    out << YAML::Key << "trigger" << YAML::Value << ToString(rig.trigger);
    out << YAML::Key << "pairing_tolerance_ms" << YAML::Value << rig.pairing_tolerance_ms;
    if (!rig.calibration_path.empty()) {
      out << YAML::Key << "calibration" << YAML::Value << rig.calibration_path;
    }
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

void GigeConfig::Save(const std::string& path) const {
  // Written beside and renamed so a reader never sees half a file.
  const std::string partial = path + ".partial";
  {
    std::ofstream file(partial, std::ios::binary | std::ios::trunc);
    if (!file) Fail(path + ": cannot write rig configuration");
    file << ToYaml();
    if (!file.flush()) Fail(path + ": write failed");
  }
  std::error_code error;
  fs::rename(partial, path, error);
  if (error) Fail(path + ": cannot rename into place: " + error.message());
}

}  // namespace romo::drivers
