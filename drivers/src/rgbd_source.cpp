// rgbd://<folder>: RGB-D frames from a folder, in the layouts public data sets use:
//   TUM RGB-D      rgb.txt + depth.txt ("timestamp file" lines), or associations.txt
//                  ("t_rgb rgb_file t_depth depth_file"); depth PNG value / 5000 = metres
//   match file     rgbd.match ("depth_file color_file" lines, Open3D); depth in mm
//   two folders    color/<stem>.* with depth/<stem>.*, paired by stem; depth in mm
//   flat pairs     <stem>.png with <stem>_depth.png (TUM samples); depth value / 5000 = metres
// Options: ?depth_scale=<units per metre>, ?max_dt_s= (TUM pairing tolerance),
// ?rate_hz= (stamps for layouts without timestamps).
// Intrinsics: a camera JSON in the folder (camera*.json or intrinsic*.json, Open3D's
// PinholeCameraIntrinsic layout {"width", "height", "intrinsic_matrix": 9 numbers column-major},
// as primesense_seq's camera_primesense.json) becomes the source's calibration (one rig, left =
// right = that K); the first in name order when there are several.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <dirent.h>
#include <fstream>
#include <map>
#include <sstream>
#include <sys/stat.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "romo/core/check.hpp"
#include "romo/core/text_file.hpp"
#include "romo/drivers/calibration.hpp"
#include "romo/drivers/frame_source.hpp"

namespace romo::drivers {
namespace {

// TUM's own associate.py pairs within 20 ms (the Kinect runs at 30 Hz: 33 ms apart).
constexpr double kDefaultMaxDtS = 0.02;
constexpr double kTumDepthScale = 5000.0;   // TUM RGB-D: 5000 units per metre
constexpr double kMillimetreScale = 1000.0;  // Kinect/PrimeSense/Open3D: millimetres
constexpr double kDefaultRateHz = 30.0;     // Kinect frame rate

struct Pair {
  std::string rgb;
  std::string depth;
  std::int64_t stamp_ns = 0;
  bool has_stamp = false;
};

bool IsFile(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

bool IsDir(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

std::vector<std::string> ListFiles(const std::string& dir) {
  std::vector<std::string> names;
  DIR* d = ::opendir(dir.c_str());
  if (d == nullptr) return names;
  while (dirent* entry = ::readdir(d)) {
    const std::string name = entry->d_name;
    if (name != "." && name != ".." && IsFile(dir + "/" + name)) names.push_back(name);
  }
  ::closedir(d);
  std::sort(names.begin(), names.end());
  return names;
}

std::string Stem(const std::string& name) { return name.substr(0, name.rfind('.')); }

bool IsImageName(const std::string& name) {
  const std::string ext = name.substr(name.rfind('.') + 1);
  return ext == "png" || ext == "jpg" || ext == "jpeg" || ext == "pgm" || ext == "ppm" ||
         ext == "tif" || ext == "tiff";
}

// Numeric stems sort as numbers (2 before 10); others as text.
bool StemLess(const std::string& a, const std::string& b) {
  char* end_a = nullptr;
  char* end_b = nullptr;
  const double na = std::strtod(a.c_str(), &end_a);
  const double nb = std::strtod(b.c_str(), &end_b);
  if (*end_a == '\0' && *end_b == '\0' && !a.empty() && !b.empty()) return na < nb;
  return a < b;
}

// Nanoseconds of a list's stamp; stamps beyond what int64 nanoseconds hold (292 years either side
// of 1970) are refused with @p where named.
std::int64_t SecondsToNs(double s, const std::string& where) {
  constexpr double kMaxS = 9.2e9;
  if (!(std::abs(s) < kMaxS)) {
    Fail(where + ": timestamp " + std::to_string(s) + " s is not a time (beyond +-9.2e9 s)");
  }
  return static_cast<std::int64_t>(std::llround(s * 1e9));
}

// "timestamp file" lines; '#' comments.
std::vector<std::pair<double, std::string>> ReadStampList(const std::string& path) {
  std::ifstream in(path);
  if (!in) Fail(path + ": cannot open");
  std::vector<std::pair<double, std::string>> entries;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream fields(line);
    double stamp = 0;
    std::string file;
    if (!(fields >> stamp >> file) || !std::isfinite(stamp)) {
      Fail(path + ":" + std::to_string(number) + ": expected 'timestamp file', got '" + line + "'");
    }
    SecondsToNs(stamp, path + ":" + std::to_string(number));
    entries.emplace_back(stamp, file);
  }
  std::sort(entries.begin(), entries.end());
  return entries;
}

std::size_t JsonKey(const std::string& text, const std::string& path, const std::string& key) {
  const std::size_t at = text.find("\"" + key + "\"");
  if (at == std::string::npos) Fail(path + ": camera JSON without \"" + key + "\"");
  return at + key.size() + 2;
}

// The number after "key": in @p text; @throws romo::Error naming @p path when it is missing.
double JsonNumber(const std::string& text, const std::string& path, const std::string& key) {
  std::size_t at = JsonKey(text, path, key);
  while (at < text.size() && (std::isspace(static_cast<unsigned char>(text[at])) || text[at] == ':')) ++at;
  char* end = nullptr;
  const double v = at < text.size() ? std::strtod(text.c_str() + at, &end) : 0.0;
  if (at >= text.size() || end == text.c_str() + at || !std::isfinite(v)) {
    Fail(path + ": \"" + key + "\" must be followed by a number");
  }
  return v;
}

// Open3D PinholeCameraIntrinsic JSON -> one rig with that K (left and right).
RigCalibration ReadCameraJson(const std::string& path) {
  const std::string text = ReadWholeFile(path, path + ": cannot open camera JSON");
  constexpr std::size_t kMaxBytes = 64 * 1024;
  if (text.size() > kMaxBytes) Fail(path + ": camera JSON larger than 64 KiB");
  const double width = JsonNumber(text, path, "width");
  const double height = JsonNumber(text, path, "height");
  std::size_t at = JsonKey(text, path, "intrinsic_matrix");
  at = text.find('[', at);
  const std::size_t close = at == std::string::npos ? at : text.find(']', at);
  if (close == std::string::npos) Fail(path + ": \"intrinsic_matrix\" must be an array of 9 numbers");
  std::vector<double> m;
  for (std::size_t p = at + 1; p < close;) {
    while (p < close && (std::isspace(static_cast<unsigned char>(text[p])) || text[p] == ',')) ++p;
    if (p >= close) break;
    char* end = nullptr;
    const double v = std::strtod(text.c_str() + p, &end);
    if (end == text.c_str() + p || !std::isfinite(v)) {
      Fail(path + ": \"intrinsic_matrix\" holds a non-number at byte " + std::to_string(p));
    }
    m.push_back(v);
    p = static_cast<std::size_t>(end - text.c_str());
  }
  if (m.size() != 9) {
    Fail(path + ": \"intrinsic_matrix\" must hold 9 numbers (column-major 3x3), got " + std::to_string(m.size()));
  }
  // Column-major: fx 0 0, 0 fy 0, cx cy 1.
  const double fx = m[0], fy = m[4], cx = m[6], cy = m[7];
  if (!(width >= 1 && height >= 1 && width <= 65536 && height <= 65536) || width != std::floor(width) ||
      height != std::floor(height)) {
    Fail(path + ": width x height " + std::to_string(width) + " x " + std::to_string(height) + " is not an image size");
  }
  if (!(fx > 0 && fy > 0) || m[1] != 0 || m[2] != 0 || m[3] != 0 || m[5] != 0 || m[8] != 1 ||
      !(cx >= 0 && cx <= width && cy >= 0 && cy <= height)) {
    Fail(path + ": \"intrinsic_matrix\" is not a pinhole K (column-major fx 0 0 0 fy 0 cx cy 1 with fx, fy > 0 "
         "and the centre in the image), got fx=" + std::to_string(fx) + " fy=" + std::to_string(fy) +
         " cx=" + std::to_string(cx) + " cy=" + std::to_string(cy));
  }
  Eigen::Matrix3d K;
  K << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  return RgbdSensorRig("rgbd", static_cast<int>(width), static_cast<int>(height), K);
}

// camera*.json / intrinsic*.json in @p folder, name order.
std::vector<std::string> CameraJsonFiles(const std::string& folder) {
  std::vector<std::string> out;
  for (const auto& name : ListFiles(folder)) {
    const bool json = name.size() > 5 && name.compare(name.size() - 5, 5, ".json") == 0;
    if (json && (name.rfind("camera", 0) == 0 || name.rfind("intrinsic", 0) == 0)) out.push_back(name);
  }
  return out;
}

class RgbdFolderSource : public FrameSource {
 public:
  RgbdFolderSource(std::string folder, std::vector<Pair> pairs, double units_per_m,
                   std::uint64_t unpaired, std::string layout)
      : folder_(std::move(folder)), pairs_(std::move(pairs)), units_per_m_(units_per_m) {
    const auto cameras = CameraJsonFiles(folder_);
    if (!cameras.empty()) {
      camera_json_ = folder_ + "/" + cameras.front();
      calibration_.rigs.push_back(ReadCameraJson(camera_json_));
      const auto& K = calibration_.rigs.front().left.K;
      status_events_.push_back(folder_ + ": intrinsics from " + cameras.front() + " (fx " + std::to_string(K(0, 0)) +
                               ", fy " + std::to_string(K(1, 1)) + ", cx " + std::to_string(K(0, 2)) + ", cy " +
                               std::to_string(K(1, 2)) + ")" +
                               (cameras.size() > 1 ? ", the first of " + std::to_string(cameras.size()) : ""));
    }
    counters_.camera_id = "rgbd:" + folder_;
    counters_.unpaired = unpaired;
    status_events_.push_back(folder_ + ": " + layout + " layout, " + std::to_string(pairs_.size()) +
                             " RGB-D pairs, depth " + std::to_string(units_per_m) +
                             " units per metre");
    if (unpaired > 0) {
      status_events_.push_back(folder_ + ": " + std::to_string(unpaired) +
                               " images without a partner within the pairing tolerance");
    }
  }

  std::optional<FrameSet> Next() override {
    if (next_ >= pairs_.size()) return std::nullopt;
    const Pair& pair = pairs_[next_];
    FrameSet set;
    set.sequence = next_;
    set.stamp_ns = pair.stamp_ns;
    RgbdFrame frame;
    frame.rgb = LoadRgb(pair.rgb);
    frame.depth = LoadDepth(pair.depth);
    if (!calibration_.rigs.empty()) {
      const RigCalibration& rig = calibration_.rigs.front();
      if (frame.depth.width != rig.width_px || frame.depth.height != rig.height_px) {
        Fail(pair.depth + ": " + std::to_string(frame.depth.width) + "x" + std::to_string(frame.depth.height) +
             " depth image, but " + camera_json_ + " is for " + std::to_string(rig.width_px) + "x" +
             std::to_string(rig.height_px));
      }
    }
    frame.depth_scale_m = 1.0 / units_per_m_;
    frame.stamp_ns = pair.stamp_ns;
    frame.sequence = next_;
    set.rgbd = std::move(frame);
    ++next_;
    ++counters_.completed;
    return set;
  }

  SourceStatus status() const override {
    SourceStatus status;
    status.cameras.push_back(counters_);
    status.events = status_events_;
    return status;
  }

  const Calibration* calibration() const override {
    return calibration_.rigs.empty() ? nullptr : &calibration_;
  }

 private:
  static Image LoadRgb(const std::string& path) {
    const cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
    if (bgr.empty()) Fail(path + ": cannot read colour image");
    Image image = Image::Allocate(PixelFormat::kRgb8, bgr.cols, bgr.rows);
    for (int y = 0; y < bgr.rows; ++y) {
      const std::uint8_t* src = bgr.ptr<std::uint8_t>(y);
      std::uint8_t* dst = image.row(y);
      for (int x = 0; x < bgr.cols; ++x) {
        dst[3 * x] = src[3 * x + 2];
        dst[3 * x + 1] = src[3 * x + 1];
        dst[3 * x + 2] = src[3 * x];
      }
    }
    return image;
  }

  static Image LoadDepth(const std::string& path) {
    const cv::Mat depth = cv::imread(path, cv::IMREAD_UNCHANGED);
    if (depth.empty()) Fail(path + ": cannot read depth image");
    if (depth.type() != CV_16UC1) {
      Fail(path + ": depth image must be 16-bit single channel, got " + std::to_string(depth.channels()) +
           " channel(s) of " + std::to_string(depth.elemSize1() * 8) + " bits");
    }
    Image image = Image::Allocate(PixelFormat::kMono16, depth.cols, depth.rows);
    for (int y = 0; y < depth.rows; ++y) {
      std::memcpy(image.row(y), depth.ptr(y), static_cast<std::size_t>(depth.cols) * 2);
    }
    return image;
  }

  std::string folder_;
  std::vector<Pair> pairs_;
  double units_per_m_;
  std::string camera_json_;
  Calibration calibration_;
  std::size_t next_ = 0;
  CameraCounters counters_;
  std::vector<std::string> status_events_;
};

// Greedy nearest-timestamp pairing (as TUM's associate.py): each depth image used once.
std::vector<Pair> PairByTimestamp(const std::string& folder,
                                  const std::vector<std::pair<double, std::string>>& rgb,
                                  const std::vector<std::pair<double, std::string>>& depth,
                                  double max_dt_s, std::uint64_t* unpaired) {
  std::vector<bool> used(depth.size(), false);
  std::vector<Pair> pairs;
  for (const auto& [t, file] : rgb) {
    const auto it = std::lower_bound(depth.begin(), depth.end(), std::make_pair(t, std::string()));
    std::ptrdiff_t best = -1;
    double best_dt = max_dt_s;
    for (auto c : {it - 1, it}) {
      if (c < depth.begin() || c >= depth.end()) continue;
      const auto index = c - depth.begin();
      const double dt = std::abs(c->first - t);
      if (!used[static_cast<std::size_t>(index)] && dt <= best_dt) {
        best = index;
        best_dt = dt;
      }
    }
    if (best < 0) {
      ++*unpaired;
      continue;
    }
    used[static_cast<std::size_t>(best)] = true;
    pairs.push_back({folder + "/" + file, folder + "/" + depth[static_cast<std::size_t>(best)].second,
                     SecondsToNs(t, folder + "/rgb.txt"), true});
  }
  *unpaired += static_cast<std::uint64_t>(std::count(used.begin(), used.end(), false));
  return pairs;
}

}  // namespace

std::unique_ptr<FrameSource> OpenRgbdSource(const Uri& uri) {
  for (const auto& [key, value] : uri.query) {
    if (key != "depth_scale" && key != "max_dt_s" && key != "rate_hz") {
      Fail(uri.ToString() + ": unknown option '" + key +
           "' (rgbd:// takes depth_scale, max_dt_s, rate_hz)");
    }
  }
  std::string folder = uri.path;
  while (folder.size() > 1 && folder.back() == '/') folder.pop_back();
  if (folder.empty()) Fail(uri.ToString() + ": no folder named (rgbd://FOLDER)");
  if (!IsDir(folder)) Fail(folder + ": RGB-D folder not found");
  const double max_dt_s = uri.GetDouble("max_dt_s").value_or(kDefaultMaxDtS);
  if (!(max_dt_s >= 0)) Fail(uri.ToString() + ": max_dt_s = " + std::to_string(max_dt_s) + " must be >= 0");
  const double rate_hz = uri.GetDouble("rate_hz").value_or(kDefaultRateHz);
  if (!(rate_hz > 0)) Fail(uri.ToString() + ": rate_hz = " + std::to_string(rate_hz) + " must be > 0");

  std::vector<Pair> pairs;
  std::uint64_t unpaired = 0;
  double units_per_m = kTumDepthScale;
  std::string layout;
  if (IsFile(folder + "/associations.txt")) {
    layout = "TUM associations.txt";
    std::ifstream in(folder + "/associations.txt");
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
      ++number;
      if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r") == std::string::npos) continue;
      std::istringstream fields(line);
      double t_rgb = 0, t_depth = 0;
      std::string rgb, depth;
      if (!(fields >> t_rgb >> rgb >> t_depth >> depth)) {
        Fail(folder + "/associations.txt:" + std::to_string(number) +
             ": expected 't_rgb rgb_file t_depth depth_file', got '" + line + "'");
      }
      pairs.push_back({folder + "/" + rgb, folder + "/" + depth,
                       SecondsToNs(t_rgb, folder + "/associations.txt:" + std::to_string(number)), true});
    }
  } else if (IsFile(folder + "/rgb.txt") && IsFile(folder + "/depth.txt")) {
    layout = "TUM rgb.txt/depth.txt";
    pairs = PairByTimestamp(folder, ReadStampList(folder + "/rgb.txt"),
                            ReadStampList(folder + "/depth.txt"), max_dt_s, &unpaired);
  } else if (IsFile(folder + "/rgbd.match")) {
    layout = "rgbd.match";
    units_per_m = kMillimetreScale;
    std::ifstream in(folder + "/rgbd.match");
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
      ++number;
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      std::istringstream fields(line);
      std::string depth, rgb;
      if (!(fields >> depth >> rgb)) {
        Fail(folder + "/rgbd.match:" + std::to_string(number) + ": expected 'depth_file color_file', got '" +
             line + "'");
      }
      pairs.push_back({folder + "/" + rgb, folder + "/" + depth, 0, false});
    }
  } else if (IsDir(folder + "/color") && IsDir(folder + "/depth")) {
    layout = "color/ + depth/";
    units_per_m = kMillimetreScale;
    std::map<std::string, std::string> depth_by_stem;
    for (const auto& name : ListFiles(folder + "/depth")) {
      if (IsImageName(name)) depth_by_stem[Stem(name)] = name;
    }
    std::vector<std::string> colors;
    for (const auto& name : ListFiles(folder + "/color")) {
      if (IsImageName(name)) colors.push_back(name);
    }
    std::sort(colors.begin(), colors.end(),
              [](const std::string& a, const std::string& b) { return StemLess(Stem(a), Stem(b)); });
    for (const auto& name : colors) {
      const auto it = depth_by_stem.find(Stem(name));
      if (it == depth_by_stem.end()) {
        ++unpaired;
        continue;
      }
      pairs.push_back({folder + "/color/" + name, folder + "/depth/" + it->second, 0, false});
      depth_by_stem.erase(it);
    }
    unpaired += depth_by_stem.size();
  } else {
    layout = "<stem>.png + <stem>_depth.png";
    std::vector<std::string> stems;
    for (const auto& name : ListFiles(folder)) {
      const std::string stem = Stem(name);
      const std::string suffix = "_depth";
      if (!IsImageName(name) || (stem.size() > suffix.size() &&
                                 stem.compare(stem.size() - suffix.size(), suffix.size(), suffix) == 0)) {
        continue;
      }
      const std::string ext = name.substr(name.rfind('.'));
      if (IsFile(folder + "/" + stem + "_depth.png")) {
        stems.push_back(stem + ext);
      }
    }
    std::sort(stems.begin(), stems.end(),
              [](const std::string& a, const std::string& b) { return StemLess(Stem(a), Stem(b)); });
    for (const auto& name : stems) {
      pairs.push_back({folder + "/" + name, folder + "/" + Stem(name) + "_depth.png", 0, false});
    }
  }
  if (pairs.empty()) {
    Fail(folder + ": no RGB-D pairs found (expected associations.txt, rgb.txt + depth.txt, "
                  "rgbd.match, color/ + depth/, or <stem>.png + <stem>_depth.png)");
  }
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    for (const std::string* file : {&pairs[i].rgb, &pairs[i].depth}) {
      if (!IsFile(*file)) Fail(folder + ": listed image " + *file + " not found");
    }
    if (!pairs[i].has_stamp) {
      pairs[i].stamp_ns = SecondsToNs(static_cast<double>(i) / rate_hz, uri.ToString() + ": frame " + std::to_string(i) + " at rate_hz");
    }
  }
  if (const auto scale = uri.GetDouble("depth_scale")) {
    if (!(*scale > 0)) Fail(uri.ToString() + ": depth_scale = " + std::to_string(*scale) + " must be > 0");
    units_per_m = *scale;
  }
  return std::make_unique<RgbdFolderSource>(folder, std::move(pairs), units_per_m, unpaired, layout);
}

}  // namespace romo::drivers
