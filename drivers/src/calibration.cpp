// Calibration I/O: OpenCV FileStorage-style YAML (%YAML:1.0, !!opencv-matrix), read with yaml-cpp
// and written here, with every field checked on the way in. Not read with cv::FileStorage: OpenCV
// 4.6's YAML parser spins for minutes on some 129-byte documents, and recordings carry this text.
#include "romo/drivers/calibration.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <locale>
#include <optional>
#include <ostream>
#include <set>
#include <sstream>
#include <dlfcn.h>
#include <sys/stat.h>

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>

#include "romo/core/check.hpp"
#include "romo/core/text_file.hpp"

namespace romo::drivers {
namespace {

// Tolerance for R^T R = I and det R = 1: calibration tools write ~1e-9, hand edits ~1e-4.
constexpr double kOrthonormalTolerance = 1e-5;
// A stereo rig whose cameras are closer than this has no usable depth.
constexpr double kMinBaselineM = 1e-3;
// Number of coefficients OpenCV accepts for a distortion model.
const std::set<std::size_t> kDistortionSizes = {0, 4, 5, 8, 12, 14};
// Six rigs take ~6 KB; the cap keeps yaml-cpp's per-node memory (~100 B each) bounded for
// hostile text (a recording's calibration message, a fuzzed file).
constexpr std::size_t kMaxCalibrationBytes = std::size_t{1} << 20;
// YAML aliases let a small text repeat one huge map many times, and each key lookup scans the
// map: with 60000 aliases of a 50000-key rig, under 1 MiB of text took minutes. Reading stops at
// counts no calibration comes near (romo has 6 rigs; a rig map has 9 keys, a matrix 4).
constexpr std::size_t kMaxRigs = 64;
constexpr std::size_t kMaxMapKeys = 32;
// Longest text quoted back in an error message.
constexpr std::size_t kMaxQuotedChars = 64;

std::string Num(double value) {
  if (std::isnan(value)) return "nan";
  std::ostringstream out;
  out << value;
  return out.str();
}

// Names origin and field in every error: "romo_sample.yaml: rigs[2].left.K: fx = -3 must be > 0".
[[noreturn]] void FieldError(const std::string& origin, const std::string& field,
                             const std::string& what) {
  Fail(origin + ": " + field + ": " + what);
}

// --- Scalars, typed the way OpenCV's reader types them (plain 12 is an integer, 12. a number,
// anything quoted is text), so files FileStorage read load to the same values. ---

bool IsQuoted(const YAML::Node& node) { return node.Tag() == "!"; }

std::optional<long long> ParseInteger(const std::string& s) {
  std::size_t start = (!s.empty() && (s[0] == '+' || s[0] == '-')) ? 1 : 0;
  if (start == s.size()) return std::nullopt;
  for (std::size_t i = start; i < s.size(); ++i) {
    if (s[i] < '0' || s[i] > '9') return std::nullopt;
  }
  long long value = 0;
  // from_chars rejects '+'; a leading '-' it handles itself.
  const char* begin = s.data() + (s[0] == '+' ? 1 : 0);
  const auto result = std::from_chars(begin, s.data() + s.size(), value);
  if (result.ec != std::errc() || result.ptr != s.data() + s.size()) return std::nullopt;
  return value;
}

std::optional<double> ParseReal(const std::string& s) {
  // YAML's and OpenCV's spellings of the special values (OpenCV writes .Nan, .Inf, -.Inf).
  std::string lower;
  for (char c : s) lower += static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  if (lower == ".nan") return std::numeric_limits<double>::quiet_NaN();
  if (lower == ".inf" || lower == "+.inf") return std::numeric_limits<double>::infinity();
  if (lower == "-.inf") return -std::numeric_limits<double>::infinity();
  // Only decimal notation: from_chars alone would also take "inf", "nan" and hex floats.
  bool has_digit = false;
  for (char c : s) {
    if (c >= '0' && c <= '9') {
      has_digit = true;
    } else if (c != '+' && c != '-' && c != '.' && c != 'e' && c != 'E') {
      return std::nullopt;
    }
  }
  if (!has_digit) return std::nullopt;
  double value = 0;
  const char* begin = s.data() + (s[0] == '+' ? 1 : 0);
  const auto result = std::from_chars(begin, s.data() + s.size(), value);
  // Out of range ("1e999") is an error of from_chars; OpenCV's strtod gives +-inf, which the
  // finiteness checks then name.
  if (result.ec == std::errc::result_out_of_range && result.ptr == s.data() + s.size()) {
    return s[0] == '-' ? -std::numeric_limits<double>::infinity()
                       : std::numeric_limits<double>::infinity();
  }
  if (result.ec != std::errc() || result.ptr != s.data() + s.size()) return std::nullopt;
  return value;
}

std::optional<int> AsInt(const YAML::Node& node) {
  if (!node.IsScalar() || IsQuoted(node)) return std::nullopt;
  const auto value = ParseInteger(node.Scalar());
  if (!value || *value < std::numeric_limits<int>::min() ||
      *value > std::numeric_limits<int>::max()) {
    return std::nullopt;
  }
  return static_cast<int>(*value);
}

std::optional<double> AsNumber(const YAML::Node& node) {
  if (!node.IsScalar() || IsQuoted(node)) return std::nullopt;
  if (const auto integer = ParseInteger(node.Scalar())) return static_cast<double>(*integer);
  return ParseReal(node.Scalar());
}

std::string NodeKind(const YAML::Node& node) {
  if (!node.IsDefined()) return "missing";
  if (node.IsNull()) return "nothing";
  if (node.IsSequence()) return "a sequence";
  if (node.IsMap()) return "a map";
  if (AsInt(node)) return "an integer";
  const std::string& text = node.Scalar();
  const std::string quoted =
      text.size() <= kMaxQuotedChars ? text : text.substr(0, kMaxQuotedChars) + "...";
  if (AsNumber(node)) return "the number " + quoted;
  return "the text '" + quoted + "'";
}

// A key of a map node; an undefined node for anything else. yaml-cpp's const operator[] throws on
// scalars (a non-const one would insert), and for a missing key returns an invalid node whose
// Type() throws InvalidNode (found by fuzzing): normalise both.
YAML::Node Child(const YAML::Node& parent, const char* key) {
  if (!parent.IsDefined() || !parent.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
  const YAML::Node& const_parent = parent;
  const YAML::Node found = const_parent[key];
  return found.IsDefined() ? found : YAML::Node(YAML::NodeType::Undefined);
}

// A map of at most kMaxMapKeys keys.
void RequireMap(const YAML::Node& node, const std::string& origin, const std::string& field) {
  if (!node.IsDefined()) FieldError(origin, field, "missing");
  if (!node.IsMap()) FieldError(origin, field, "expected a map, got " + NodeKind(node));
  if (node.size() > kMaxMapKeys) {
    FieldError(origin, field,
               "a map of " + std::to_string(node.size()) + " keys, more than the " +
                   std::to_string(kMaxMapKeys) + " any calibration map has");
  }
}

// Refuses a sequence longer than the matrix it fills before reading a single number.
// @p what names the matrix in the error ("a 3x3 matrix").
void RequireAtMost(const YAML::Node& seq, std::size_t max_values, const std::string& what,
                   const std::string& origin, const std::string& field) {
  if (seq.size() > max_values) {
    FieldError(origin, field, std::to_string(seq.size()) + " numbers, too many for " + what);
  }
}

int ReadInt(const YAML::Node& parent, const char* key, const std::string& origin,
            const std::string& field) {
  const YAML::Node node = Child(parent, key);
  if (!node.IsDefined()) FieldError(origin, field, "missing");
  const auto value = AsInt(node);
  if (!value) FieldError(origin, field, "expected an integer, got " + NodeKind(node));
  return *value;
}

std::string ReadString(const YAML::Node& parent, const char* key, const std::string& origin,
                       const std::string& field) {
  const YAML::Node node = Child(parent, key);
  if (!node.IsDefined()) FieldError(origin, field, "missing");
  if (!node.IsScalar() || (!IsQuoted(node) && AsNumber(node))) {
    FieldError(origin, field, "expected text, got " + NodeKind(node));
  }
  return node.Scalar();
}

// A matrix read from YAML, row-major.
struct Matrix {
  int rows = 0;
  int cols = 0;
  std::vector<double> values;
  double at(int r, int c) const { return values[static_cast<std::size_t>(r) * cols + c]; }
};

std::vector<double> ReadNumbers(const YAML::Node& seq, const std::string& origin,
                                const std::string& field) {
  std::vector<double> values;
  values.reserve(seq.size());
  for (const auto& item : seq) {
    const auto value = AsNumber(item);
    if (!value) FieldError(origin, field, "expected numbers, got " + NodeKind(item));
    values.push_back(*value);
  }
  return values;
}

// Element types of an opencv-matrix (dt); values are stored as that type, so a file whose dt is
// f or an integer type loads with the rounding FileStorage applied.
double StoreAs(char dt, double value) {
  const auto saturate = [&](double lo, double hi) {
    return std::isnan(value) ? 0.0 : std::min(hi, std::max(lo, std::nearbyint(value)));
  };
  switch (dt) {
    case 'u': return saturate(0, 255);
    case 'c': return saturate(-128, 127);
    case 'w': return saturate(0, 65535);
    case 's': return saturate(-32768, 32767);
    case 'i': return saturate(std::numeric_limits<int>::min(), std::numeric_limits<int>::max());
    case 'f': return static_cast<double>(static_cast<float>(value));
    default: return value;  // 'd'
  }
}

// Reads an !!opencv-matrix (or a plain sequence of numbers, as a 1xN row).
Matrix ReadMat(const YAML::Node& parent, const char* key, std::size_t max_values,
               const std::string& what, const std::string& origin, const std::string& field) {
  const YAML::Node node = Child(parent, key);
  if (!node.IsDefined()) FieldError(origin, field, "missing");
  Matrix mat;
  if (node.IsSequence()) {
    RequireAtMost(node, max_values, what, origin, field);
    mat.values = ReadNumbers(node, origin, field);
    if (!mat.values.empty()) {
      mat.rows = 1;
      mat.cols = static_cast<int>(mat.values.size());
    }
    return mat;
  }
  if (!node.IsMap()) FieldError(origin, field, "expected a matrix, got " + NodeKind(node));
  RequireMap(node, origin, field);
  const YAML::Node rows = Child(node, "rows"), cols = Child(node, "cols");
  const YAML::Node dt = Child(node, "dt"), data = Child(node, "data");
  const auto r = AsInt(rows), c = AsInt(cols);
  if (!r || *r < 0) FieldError(origin, field + ".rows", "expected a count, got " + NodeKind(rows));
  if (!c || *c < 0) FieldError(origin, field + ".cols", "expected a count, got " + NodeKind(cols));
  // Single-channel element types only: a calibration matrix has one number per element.
  const std::string type = dt.IsScalar() ? dt.Scalar() : "";
  if (type.size() != 1 || std::string("ucwsifd").find(type[0]) == std::string::npos) {
    FieldError(origin, field + ".dt",
               "expected one of u, c, w, s, i, f, d, got " + NodeKind(dt));
  }
  if (!data.IsSequence()) {
    FieldError(origin, field + ".data", "expected a sequence, got " + NodeKind(data));
  }
  RequireAtMost(data, max_values, what, origin, field + ".data");
  mat.values = ReadNumbers(data, origin, field + ".data");
  if (static_cast<double>(*r) * *c != static_cast<double>(mat.values.size())) {
    FieldError(origin, field,
               "opencv-matrix rows x cols = " + std::to_string(*r) + "x" + std::to_string(*c) +
                   " does not match its " + std::to_string(mat.values.size()) + " numbers");
  }
  for (double& value : mat.values) value = StoreAs(type[0], value);
  if (!mat.values.empty()) {
    mat.rows = *r;
    mat.cols = *c;
  }
  return mat;
}

Matrix ReadMatSized(const YAML::Node& parent, const char* key, int rows, int cols,
                    const std::string& origin, const std::string& field) {
  // Up to twice the size is read, so that a near miss (12 numbers for 4x4) is named by its shape.
  const std::string shape = std::to_string(rows) + "x" + std::to_string(cols);
  Matrix mat = ReadMat(parent, key, 2 * static_cast<std::size_t>(rows * cols), "a " + shape + " matrix",
                       origin, field);
  // Hand-written files may give a plain row-major list of numbers instead of an opencv-matrix.
  if (mat.rows == 1 && mat.cols == rows * cols) {
    mat.rows = rows;
    mat.cols = cols;
  }
  if (mat.rows != rows || mat.cols != cols) {
    FieldError(origin, field,
               "expected a " + std::to_string(rows) + "x" + std::to_string(cols) + " matrix, got " +
                   std::to_string(mat.rows) + "x" + std::to_string(mat.cols));
  }
  for (int r = 0; r < mat.rows; ++r) {
    for (int c = 0; c < mat.cols; ++c) {
      if (!std::isfinite(mat.at(r, c))) {
        FieldError(origin, field, "element (" + std::to_string(r) + "," + std::to_string(c) +
                                      ") = " + Num(mat.at(r, c)) + " is not finite");
      }
    }
  }
  return mat;
}

template <typename Derived>
void CopyTo(const Matrix& mat, Eigen::MatrixBase<Derived>* out) {
  for (int r = 0; r < mat.rows; ++r) {
    for (int c = 0; c < mat.cols; ++c) (*out)(r, c) = mat.at(r, c);
  }
}

CameraIntrinsics ReadCamera(const YAML::Node& parent, const char* key, const std::string& origin,
                            const std::string& field) {
  const YAML::Node node = Child(parent, key);
  if (!node.IsDefined()) FieldError(origin, field, "missing");
  RequireMap(node, origin, field);
  CameraIntrinsics camera;
  CopyTo(ReadMatSized(node, "K", 3, 3, origin, field + ".K"), &camera.K);
  if (!Child(node, "distortion").IsDefined()) {
    FieldError(origin, field + ".distortion", "missing (write [] for none)");
  }
  const Matrix d = ReadMat(node, "distortion", *kDistortionSizes.rbegin(),
                           "a distortion model (at most 14)", origin, field + ".distortion");
  if (!d.values.empty() && d.rows != 1 && d.cols != 1) {
    FieldError(origin, field + ".distortion",
               "expected a vector, got " + std::to_string(d.rows) + "x" + std::to_string(d.cols));
  }
  camera.distortion = d.values;  // a row or a column: row-major order is the vector order
  return camera;
}

// --- Writing: the layout cv::FileStorage writes (so OpenCV tools still read the files), with
// shortest round-trip numbers and quoted names, so that every valid calibration reads back equal.

std::string NumberText(double value) {
  if (std::isnan(value)) return ".nan";
  if (std::isinf(value)) return value > 0 ? ".inf" : "-.inf";
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

// Double-quoted unless the name is a plain word that no YAML reader takes for a number, bool or
// null; Validate allows only printable ASCII, so \" and \\ are the only escapes needed.
std::string NameText(const std::string& name) {
  static const std::set<std::string> kSpecial = {"null", "Null", "NULL", "true", "True", "TRUE",
                                                 "false", "False", "FALSE", "yes", "Yes", "YES",
                                                 "no", "No", "NO", "on", "On", "ON", "off",
                                                 "Off", "OFF", "y", "Y", "n", "N"};
  bool plain = !name.empty() && kSpecial.count(name) == 0 &&
               ((name[0] >= 'a' && name[0] <= 'z') || (name[0] >= 'A' && name[0] <= 'Z') ||
                name[0] == '_');
  for (char c : name) {
    plain = plain && ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                      (c >= '0' && c <= '9') || c == '_' || c == '-');
  }
  if (plain) return name;
  std::string quoted = "\"";
  for (char c : name) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return quoted + "\"";
}

std::string NumberList(const double* values, std::size_t count) {
  if (count == 0) return "[]";
  std::string text = "[ ";
  for (std::size_t i = 0; i < count; ++i) text += (i ? ", " : "") + NumberText(values[i]);
  return text + " ]";
}

template <typename Derived>
void WriteMatrix(std::ostream& out, const std::string& indent, const char* key,
                 const Eigen::MatrixBase<Derived>& m) {
  std::vector<double> row_major;
  for (int r = 0; r < m.rows(); ++r) {
    for (int c = 0; c < m.cols(); ++c) row_major.push_back(m(r, c));
  }
  out << indent << key << ": !!opencv-matrix\n"
      << indent << "   rows: " << m.rows() << "\n"
      << indent << "   cols: " << m.cols() << "\n"
      << indent << "   dt: d\n"
      << indent << "   data: " << NumberList(row_major.data(), row_major.size()) << "\n";
}

void WriteCamera(std::ostream& out, const char* key, const CameraIntrinsics& camera) {
  out << "      " << key << ":\n";
  WriteMatrix(out, "         ", "K", camera.K);
  out << "         distortion: "
      << NumberList(camera.distortion.data(), camera.distortion.size()) << "\n";
}

void ValidateCamera(const CameraIntrinsics& camera, int width, int height,
                    const std::string& origin, const std::string& field) {
  const Eigen::Matrix3d& K = camera.K;
  const std::string k_field = field + ".K";
  if (!(K(0, 0) > 0)) FieldError(origin, k_field, "fx = " + Num(K(0, 0)) + " must be > 0");
  if (!(K(1, 1) > 0)) FieldError(origin, k_field, "fy = " + Num(K(1, 1)) + " must be > 0");
  if (!(K(0, 2) >= 0 && K(0, 2) <= width)) {
    FieldError(origin, k_field,
               "cx = " + Num(K(0, 2)) + " must lie in [0, width = " + std::to_string(width) + "]");
  }
  if (!(K(1, 2) >= 0 && K(1, 2) <= height)) {
    FieldError(origin, k_field,
               "cy = " + Num(K(1, 2)) + " must lie in [0, height = " + std::to_string(height) + "]");
  }
  if (K(1, 0) != 0 || K(2, 0) != 0 || K(2, 1) != 0 || K(2, 2) != 1) {
    FieldError(origin, k_field, "must be upper triangular with K(2,2) = 1, got row 3 = (" +
                                    Num(K(2, 0)) + ", " + Num(K(2, 1)) + ", " + Num(K(2, 2)) +
                                    ")");
  }
  if (kDistortionSizes.count(camera.distortion.size()) == 0) {
    FieldError(origin, field + ".distortion",
               std::to_string(camera.distortion.size()) +
                   " coefficients; OpenCV models have 0, 4, 5, 8, 12 or 14");
  }
  for (std::size_t i = 0; i < camera.distortion.size(); ++i) {
    if (!std::isfinite(camera.distortion[i])) {
      FieldError(origin, field + ".distortion",
                 "coefficient " + std::to_string(i) + " = " + Num(camera.distortion[i]) +
                     " is not finite");
    }
  }
}

void ValidateRotation(const Eigen::Matrix3d& R, const std::string& origin,
                      const std::string& field) {
  const double orthonormal_error = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
  if (!(orthonormal_error <= kOrthonormalTolerance)) {
    FieldError(origin, field,
               "rotation is not orthonormal: |R^T R - I| = " + Num(orthonormal_error) +
                   " exceeds " + Num(kOrthonormalTolerance));
  }
  const double det = R.determinant();
  if (!(std::abs(det - 1.0) <= kOrthonormalTolerance)) {
    FieldError(origin, field, "rotation has det = " + Num(det) + ", must be +1 (a reflection?)");
  }
}

bool FileExists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

Calibration Parse(const YAML::Node& root, const std::string& origin) {
  if (!root.IsMap()) FieldError(origin, "document", "expected a map with 'rigs', got " + NodeKind(root));
  const YAML::Node rigs = Child(root, "rigs");
  if (!rigs.IsDefined()) FieldError(origin, "rigs", "missing");
  if (!rigs.IsSequence()) FieldError(origin, "rigs", "expected a sequence, got " + NodeKind(rigs));
  if (rigs.size() > kMaxRigs) {
    FieldError(origin, "rigs",
               std::to_string(rigs.size()) + " rigs, more than the " + std::to_string(kMaxRigs) +
                   " a calibration may hold");
  }
  Calibration calibration;
  int index = 0;
  for (const auto& node : rigs) {
    const std::string f = "rigs[" + std::to_string(index++) + "]";
    RequireMap(node, origin, f);
    RigCalibration rig;
    rig.rig_id = ReadInt(node, "id", origin, f + ".id");
    rig.name = ReadString(node, "name", origin, f + ".name");
    rig.width_px = ReadInt(node, "image_width", origin, f + ".image_width");
    rig.height_px = ReadInt(node, "image_height", origin, f + ".image_height");
    rig.left = ReadCamera(node, "left", origin, f + ".left");
    rig.right = ReadCamera(node, "right", origin, f + ".right");
    CopyTo(ReadMatSized(node, "R", 3, 3, origin, f + ".R"), &rig.R);
    CopyTo(ReadMatSized(node, "T", 3, 1, origin, f + ".T"), &rig.T);
    const Matrix pose = ReadMatSized(node, "T_vehicle_rig", 4, 4, origin, f + ".T_vehicle_rig");
    Eigen::Matrix4d m;
    CopyTo(pose, &m);
    if (m(3, 0) != 0 || m(3, 1) != 0 || m(3, 2) != 0 || m(3, 3) != 1) {
      FieldError(origin, f + ".T_vehicle_rig",
                 "last row must be (0, 0, 0, 1), got (" + Num(m(3, 0)) + ", " + Num(m(3, 1)) +
                     ", " + Num(m(3, 2)) + ", " + Num(m(3, 3)) + ")");
    }
    rig.T_vehicle_rig.matrix() = m;
    calibration.rigs.push_back(std::move(rig));
  }
  calibration.Validate(origin);
  return calibration;
}

Calibration ParseText(std::string text, const std::string& origin) {
  if (text.size() > kMaxCalibrationBytes) {
    Fail(origin + ": calibration text is " + std::to_string(text.size()) + " bytes, over the " +
         std::to_string(kMaxCalibrationBytes) + " any calibration needs");
  }
  // OpenCV's "%YAML:1.0" header is not YAML's "%YAML 1.0" directive: read it as a comment, so the
  // document parses the same with or without it (and line numbers in errors stay right).
  if (text.compare(0, 6, "%YAML:") == 0) text[0] = '#';
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::DeepRecursion& e) {  // yaml-cpp's own message for it is "bad file"
    Fail(origin + ": not a valid YAML calibration: line " + std::to_string(e.mark.line + 1) +
         ", column " + std::to_string(e.mark.column + 1) + ": nested " +
         std::to_string(e.depth()) + " levels deep, deeper than the YAML reader allows");
  } catch (const YAML::ParserException& e) {
    Fail(origin + ": not a valid YAML calibration: line " + std::to_string(e.mark.line + 1) +
         ", column " + std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
  return Parse(root, origin);
}

}  // namespace

const RigCalibration& Calibration::rig(int rig_id) const {
  for (const auto& r : rigs) {
    if (r.rig_id == rig_id) return r;
  }
  Fail("calibration has no rig with id " + std::to_string(rig_id) + " (it has " +
       std::to_string(rigs.size()) + " rigs)");
}

void Calibration::Validate(const std::string& origin) const {
  if (rigs.empty()) FieldError(origin, "rigs", "no rigs");
  if (rigs.size() > kMaxRigs) {  // as Load refuses it, so that what Save writes loads again
    FieldError(origin, "rigs",
               std::to_string(rigs.size()) + " rigs, more than the " + std::to_string(kMaxRigs) +
                   " a calibration may hold");
  }
  std::set<int> ids;
  for (std::size_t i = 0; i < rigs.size(); ++i) {
    const RigCalibration& rig = rigs[i];
    const std::string f = "rigs[" + std::to_string(i) + "]";
    if (rig.rig_id < 0) FieldError(origin, f + ".id", "id = " + std::to_string(rig.rig_id) + " must be >= 0");
    if (!ids.insert(rig.rig_id).second) {
      FieldError(origin, f + ".id", "duplicate rig id " + std::to_string(rig.rig_id));
    }
    if (rig.name.empty()) FieldError(origin, f + ".name", "empty");
    for (std::size_t c = 0; c < rig.name.size(); ++c) {
      // Names label rigs in logs and UIs; printable ASCII also keeps the YAML quoting simple.
      const auto byte = static_cast<unsigned char>(rig.name[c]);
      if (byte < 0x20 || byte > 0x7e) {
        char hex[8];
        std::snprintf(hex, sizeof(hex), "0x%02x", byte);
        FieldError(origin, f + ".name",
                   "byte " + std::to_string(c) + " is " + hex + "; names are printable ASCII");
      }
    }
    if (rig.width_px <= 0) {
      FieldError(origin, f + ".image_width", "width = " + std::to_string(rig.width_px) + " must be > 0");
    }
    if (rig.height_px <= 0) {
      FieldError(origin, f + ".image_height",
                 "height = " + std::to_string(rig.height_px) + " must be > 0");
    }
    ValidateCamera(rig.left, rig.width_px, rig.height_px, origin, f + ".left");
    ValidateCamera(rig.right, rig.width_px, rig.height_px, origin, f + ".right");
    ValidateRotation(rig.R, origin, f + ".R");
    if (!rig.T.allFinite()) FieldError(origin, f + ".T", "not finite");
    if (!(rig.baseline_m() >= kMinBaselineM)) {
      FieldError(origin, f + ".T",
                 "baseline |T| = " + Num(rig.baseline_m()) + " m must be >= " + Num(kMinBaselineM) +
                     " m");
    }
    const Eigen::Matrix4d& m = rig.T_vehicle_rig.matrix();
    if (!m.allFinite()) FieldError(origin, f + ".T_vehicle_rig", "not finite");
    ValidateRotation(rig.T_vehicle_rig.linear(), origin, f + ".T_vehicle_rig");
  }
}

Calibration Calibration::Load(const std::string& path) {
  if (!FileExists(path)) Fail(path + ": calibration file not found");
  return ParseText(ReadWholeFile(path, path + ": cannot open calibration file"), path);
}

Calibration Calibration::FromYaml(const std::string& yaml_text, const std::string& origin) {
  if (yaml_text.empty()) Fail(origin + ": empty calibration text");
  return ParseText(yaml_text, origin);
}

std::string Calibration::ToYaml() const {
  std::ostringstream out;
  out.imbue(std::locale::classic());  // no digit grouping from a global locale in integers
  out << "%YAML:1.0\n---\nrigs:\n";
  for (const auto& rig : rigs) {
    out << "   -\n"
        << "      id: " << rig.rig_id << "\n"
        << "      name: " << NameText(rig.name) << "\n"
        << "      image_width: " << rig.width_px << "\n"
        << "      image_height: " << rig.height_px << "\n";
    WriteCamera(out, "left", rig.left);
    WriteCamera(out, "right", rig.right);
    WriteMatrix(out, "      ", "R", rig.R);
    WriteMatrix(out, "      ", "T", rig.T);
    WriteMatrix(out, "      ", "T_vehicle_rig", rig.T_vehicle_rig.matrix());
  }
  return out.str();
}

void Calibration::Save(const std::string& path) const {
  Validate(path);
  const std::string text = ToYaml();
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (file == nullptr) Fail(path + ": cannot create calibration file");
  const bool ok = std::fwrite(text.data(), 1, text.size(), file) == text.size();
  if (std::fclose(file) != 0 || !ok) Fail(path + ": cannot write calibration file");
}

RigCalibration RgbdSensorRig(const std::string& name, int width_px, int height_px, const Eigen::Matrix3d& K) {
  constexpr double kDepthToRgbBaselineM = 0.025;  // Kinect v1 / PrimeSense
  RigCalibration rig;
  rig.rig_id = 0;
  rig.name = name;
  rig.width_px = width_px;
  rig.height_px = height_px;
  rig.left.K = K;
  rig.right.K = K;
  rig.T << -kDepthToRgbBaselineM, 0, 0;
  return rig;
}

std::string SampleCalibrationPath() {
  const std::string relative = "/calibration/romo_sample.yaml";
  std::vector<std::string> dirs;
  // An installed library finds the data installed beside it, wherever the prefix was moved.
  Dl_info info{};
  if (::dladdr(reinterpret_cast<void*>(&SampleCalibrationPath), &info) != 0 &&
      info.dli_fname != nullptr) {
    const std::string library = info.dli_fname;
    const auto slash = library.rfind('/');
    if (slash != std::string::npos) {
      dirs.push_back(library.substr(0, slash) + "/" + ROMO_CONFIG_DIR_FROM_LIBDIR);
    }
  }
  dirs.push_back(ROMO_SOURCE_CONFIG_DIR);
  dirs.push_back(ROMO_INSTALL_CONFIG_DIR);
  std::string tried;
  for (const std::string& dir : dirs) {
    if (FileExists(dir + relative)) return dir + relative;
    tried += (tried.empty() ? "" : ", ") + dir;
  }
  Fail("sample calibration" + relative + " not found in " + tried);
}

}  // namespace romo::drivers
