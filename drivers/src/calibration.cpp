// Calibration I/O through OpenCV FileStorage YAML, with every field checked on the way in.
#include "romo/drivers/calibration.hpp"

#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>
#include <dlfcn.h>
#include <sys/stat.h>

#include <opencv2/core.hpp>

#include "romo/core/check.hpp"

namespace romo::drivers {
namespace {

// Tolerance for R^T R = I and det R = 1: calibration tools write ~1e-9, hand edits ~1e-4.
constexpr double kOrthonormalTolerance = 1e-5;
// A stereo rig whose cameras are closer than this has no usable depth.
constexpr double kMinBaselineM = 1e-3;
// Number of coefficients OpenCV accepts for a distortion model.
const std::set<std::size_t> kDistortionSizes = {0, 4, 5, 8, 12, 14};

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

std::string NodeKind(const cv::FileNode& node) {
  if (node.isNone()) return "missing";
  if (node.isInt()) return "an integer";
  if (node.isReal()) return "a number";
  if (node.isString()) return "the text '" + static_cast<std::string>(node) + "'";
  if (node.isSeq()) return "a sequence";
  if (node.isMap()) return "a map";
  return "an unknown node";
}

int ReadInt(const cv::FileNode& parent, const char* key, const std::string& origin,
            const std::string& field) {
  const cv::FileNode node = parent[key];
  if (node.isNone()) FieldError(origin, field, "missing");
  if (!node.isInt()) FieldError(origin, field, "expected an integer, got " + NodeKind(node));
  return static_cast<int>(node);
}

std::string ReadString(const cv::FileNode& parent, const char* key, const std::string& origin,
                       const std::string& field) {
  const cv::FileNode node = parent[key];
  if (node.isNone()) FieldError(origin, field, "missing");
  if (!node.isString()) FieldError(origin, field, "expected text, got " + NodeKind(node));
  return static_cast<std::string>(node);
}

// Reads an !!opencv-matrix (or a plain sequence of numbers, as a 1xN row) into doubles.
cv::Mat ReadMat(const cv::FileNode& parent, const char* key, const std::string& origin,
                const std::string& field) {
  const cv::FileNode node = parent[key];
  if (node.isNone()) FieldError(origin, field, "missing");
  cv::Mat mat;
  try {
    if (node.isSeq()) {
      std::vector<double> values;
      for (const auto& item : node) {
        if (!item.isInt() && !item.isReal()) {
          FieldError(origin, field, "expected numbers, got " + NodeKind(item));
        }
        values.push_back(static_cast<double>(item));
      }
      if (!values.empty()) mat = cv::Mat(values, true).reshape(1, 1);
    } else if (node.isMap()) {
      // OpenCV allocates rows x cols before it counts the data (a one-line corrupt size asked
      // for 48 GB): the declared size must not exceed the numbers given.
      const cv::FileNode rows = node["rows"], cols = node["cols"], data = node["data"];
      if (!rows.isInt() || !cols.isInt() || !data.isSeq() || static_cast<int>(rows) < 0 ||
          static_cast<int>(cols) < 0 ||
          static_cast<double>(static_cast<int>(rows)) * static_cast<int>(cols) >
              static_cast<double>(data.size())) {
        FieldError(origin, field, "opencv-matrix rows x cols do not match its data");
      }
      node >> mat;
    }
  } catch (const cv::Exception& e) {
    FieldError(origin, field, std::string("not a matrix: ") + e.what());
  }
  if (mat.empty() && !node.isSeq()) {
    FieldError(origin, field, "expected a matrix, got " + NodeKind(node));
  }
  if (!mat.empty()) mat.convertTo(mat, CV_64F);
  return mat;
}

cv::Mat ReadMatSized(const cv::FileNode& parent, const char* key, int rows, int cols,
                     const std::string& origin, const std::string& field) {
  cv::Mat mat = ReadMat(parent, key, origin, field);
  // Hand-written files may give a plain row-major list of numbers instead of an opencv-matrix.
  if (mat.rows == 1 && mat.cols == rows * cols) mat = mat.reshape(1, rows).clone();
  if (mat.rows != rows || mat.cols != cols) {
    FieldError(origin, field,
               "expected a " + std::to_string(rows) + "x" + std::to_string(cols) + " matrix, got " +
                   std::to_string(mat.rows) + "x" + std::to_string(mat.cols));
  }
  for (int r = 0; r < mat.rows; ++r) {
    for (int c = 0; c < mat.cols; ++c) {
      if (!std::isfinite(mat.at<double>(r, c))) {
        FieldError(origin, field, "element (" + std::to_string(r) + "," + std::to_string(c) +
                                      ") = " + Num(mat.at<double>(r, c)) + " is not finite");
      }
    }
  }
  return mat;
}

template <typename Derived>
void CopyTo(const cv::Mat& mat, Eigen::MatrixBase<Derived>* out) {
  for (int r = 0; r < mat.rows; ++r) {
    for (int c = 0; c < mat.cols; ++c) (*out)(r, c) = mat.at<double>(r, c);
  }
}

template <typename Derived>
cv::Mat ToMat(const Eigen::MatrixBase<Derived>& m) {
  cv::Mat mat(static_cast<int>(m.rows()), static_cast<int>(m.cols()), CV_64F);
  for (int r = 0; r < mat.rows; ++r) {
    for (int c = 0; c < mat.cols; ++c) mat.at<double>(r, c) = m(r, c);
  }
  return mat;
}

CameraIntrinsics ReadCamera(const cv::FileNode& node, const std::string& origin,
                            const std::string& field) {
  if (node.isNone()) FieldError(origin, field, "missing");
  if (!node.isMap()) FieldError(origin, field, "expected a map, got " + NodeKind(node));
  CameraIntrinsics camera;
  CopyTo(ReadMatSized(node, "K", 3, 3, origin, field + ".K"), &camera.K);
  const cv::FileNode dist = node["distortion"];
  if (dist.isNone()) FieldError(origin, field + ".distortion", "missing (write [] for none)");
  const cv::Mat d = ReadMat(node, "distortion", origin, field + ".distortion");
  if (!d.empty() && d.rows != 1 && d.cols != 1) {
    FieldError(origin, field + ".distortion",
               "expected a vector, got " + std::to_string(d.rows) + "x" + std::to_string(d.cols));
  }
  for (int i = 0; i < static_cast<int>(d.total()); ++i) {
    camera.distortion.push_back(d.at<double>(d.rows == 1 ? 0 : i, d.rows == 1 ? i : 0));
  }
  return camera;
}

void WriteCamera(cv::FileStorage& fs, const char* key, const CameraIntrinsics& camera) {
  fs << key << "{";
  fs << "K" << ToMat(camera.K);
  fs << "distortion" << "[:";
  for (double k : camera.distortion) fs << k;
  fs << "]";
  fs << "}";
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

Calibration Parse(cv::FileStorage& fs, const std::string& origin) {
  const cv::FileNode rigs = fs["rigs"];
  if (rigs.isNone()) FieldError(origin, "rigs", "missing");
  if (!rigs.isSeq()) FieldError(origin, "rigs", "expected a sequence, got " + NodeKind(rigs));
  Calibration calibration;
  int index = 0;
  for (const auto& node : rigs) {
    const std::string f = "rigs[" + std::to_string(index++) + "]";
    if (!node.isMap()) FieldError(origin, f, "expected a map, got " + NodeKind(node));
    RigCalibration rig;
    rig.rig_id = ReadInt(node, "id", origin, f + ".id");
    rig.name = ReadString(node, "name", origin, f + ".name");
    rig.width_px = ReadInt(node, "image_width", origin, f + ".image_width");
    rig.height_px = ReadInt(node, "image_height", origin, f + ".image_height");
    rig.left = ReadCamera(node["left"], origin, f + ".left");
    rig.right = ReadCamera(node["right"], origin, f + ".right");
    CopyTo(ReadMatSized(node, "R", 3, 3, origin, f + ".R"), &rig.R);
    CopyTo(ReadMatSized(node, "T", 3, 1, origin, f + ".T"), &rig.T);
    const cv::Mat pose = ReadMatSized(node, "T_vehicle_rig", 4, 4, origin, f + ".T_vehicle_rig");
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

// FileNode accessors assert (cv::Exception) on nodes of a kind Parse does not expect (a document
// whose root is not a map, found by fuzzing); name the origin instead.
Calibration ParseOrFail(cv::FileStorage& fs, const std::string& origin) {
  try {
    return Parse(fs, origin);
  } catch (const cv::Exception& e) {
    Fail(origin + ": malformed calibration: " + e.err);
  }
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
  std::set<int> ids;
  for (std::size_t i = 0; i < rigs.size(); ++i) {
    const RigCalibration& rig = rigs[i];
    const std::string f = "rigs[" + std::to_string(i) + "]";
    if (rig.rig_id < 0) FieldError(origin, f + ".id", "id = " + std::to_string(rig.rig_id) + " must be >= 0");
    if (!ids.insert(rig.rig_id).second) {
      FieldError(origin, f + ".id", "duplicate rig id " + std::to_string(rig.rig_id));
    }
    if (rig.name.empty()) FieldError(origin, f + ".name", "empty");
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
  cv::FileStorage fs;
  try {
    if (!fs.open(path, cv::FileStorage::READ)) Fail(path + ": cannot open calibration file");
  } catch (const cv::Exception& e) {
    Fail(path + ": not a valid YAML calibration file: " + e.err);
  } catch (const std::exception& e) {  // OpenCV's parser also throws std::length_error
    Fail(path + ": not a valid YAML calibration file: " + e.what());
  }
  return ParseOrFail(fs, path);
}

Calibration Calibration::FromYaml(const std::string& yaml_text, const std::string& origin) {
  if (yaml_text.empty()) Fail(origin + ": empty calibration text");
  cv::FileStorage fs;
  try {
    if (!fs.open(yaml_text, cv::FileStorage::READ | cv::FileStorage::MEMORY)) {
      Fail(origin + ": cannot parse calibration text");
    }
  } catch (const cv::Exception& e) {
    Fail(origin + ": not a valid YAML calibration: " + e.err);
  } catch (const std::exception& e) {  // OpenCV's parser also throws std::length_error
    Fail(origin + ": not a valid YAML calibration: " + e.what());
  }
  return ParseOrFail(fs, origin);
}

std::string Calibration::ToYaml() const {
  cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY |
                                 cv::FileStorage::FORMAT_YAML);
  fs << "rigs" << "[";
  for (const auto& rig : rigs) {
    fs << "{";
    fs << "id" << rig.rig_id;
    fs << "name" << rig.name;
    fs << "image_width" << rig.width_px;
    fs << "image_height" << rig.height_px;
    WriteCamera(fs, "left", rig.left);
    WriteCamera(fs, "right", rig.right);
    fs << "R" << ToMat(rig.R);
    fs << "T" << ToMat(rig.T);
    fs << "T_vehicle_rig" << ToMat(rig.T_vehicle_rig.matrix());
    fs << "}";
  }
  fs << "]";
  return fs.releaseAndGetString();
}

void Calibration::Save(const std::string& path) const {
  Validate(path);
  const std::string text = ToYaml();
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (file == nullptr) Fail(path + ": cannot create calibration file");
  const bool ok = std::fwrite(text.data(), 1, text.size(), file) == text.size();
  if (std::fclose(file) != 0 || !ok) Fail(path + ": cannot write calibration file");
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
