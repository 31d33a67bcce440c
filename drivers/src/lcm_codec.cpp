#include "lcm_codec.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <sys/stat.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "romo/core/check.hpp"
#include "romo/drivers/lcm_walker.hpp"
#include "romo_lcm/calibration_t.hpp"
#include "romo_lcm/gnss_fix_t.hpp"
#include "romo_lcm/rgbd_frame_t.hpp"
#include "romo_lcm/stereo_frame_t.hpp"
#include "romo_lcm/vehicle_state_t.hpp"

namespace romo::drivers::lcm_codec {
namespace {

constexpr std::uint32_t kLogSyncWord = 0xEDA1DA01;
// lcm-logger's header: sync, event number, timestamp, channel length, data length.
constexpr int kEventHeaderBytes = 4 + 8 + 8 + 4 + 4;
// LCM limits channel names to 63 bytes; anything much longer is a damaged header.
constexpr std::int32_t kMaxChannelBytes = 1024;
// Larger than any frame set we write (12 raw 16-bit 782x582 images are ~11 MB).
constexpr std::int32_t kMaxEventBytes = 1 << 30;
constexpr std::int64_t kMaxTimestampUs = std::numeric_limits<std::int64_t>::max() / 1000;

template <typename Msg>
std::vector<std::uint8_t> Encode(const Msg& msg) {
  std::vector<std::uint8_t> out(static_cast<std::size_t>(msg.getEncodedSize()));
  const int n = msg.encode(out.data(), 0, static_cast<int>(out.size()));
  ROMO_DEMAND(n == static_cast<int>(out.size()));
  return out;
}

// image_t: stamp_ns, sequence, camera_id, width, height, stride, pixel_format, encoding, size,
// data[size].
bool WalkImage(LcmWalker& w) {
  return w.Skip(8 + 8) && w.String("camera_id") && w.Skip(4 + 4 + 4 + 1 + 1) &&
         w.FixedArray(1, "size");
}

// stereo_frame_t / rgbd_frame_t: the hash, @p fixed_bytes of fixed fields, then two image_t.
// A message of the type whose image sizes do not fit its bytes is rejected before the generated
// decoder allocates them (a 60-byte message could ask for 2 x 2 GB).
void CheckImageCounts(const std::vector<std::uint8_t>& data, std::int64_t hash,
                      std::size_t fixed_bytes, const char* type, const std::string& origin) {
  if (!LcmHashMatches(data.data(), data.size(), hash)) return;  // Decode names the wrong type
  LcmWalker w(data.data(), data.size());
  if (!(w.Skip(8 + fixed_bytes) && WalkImage(w) && WalkImage(w))) {
    Fail(origin + ": " + w.Reason(std::string("romo_lcm.") + type));
  }
}

template <typename Msg>
Msg Decode(const std::vector<std::uint8_t>& data, const std::string& origin) {
  Msg msg;
  int n = -1;
  try {
    n = msg.decode(data.data(), 0, static_cast<int>(data.size()));
  } catch (const std::exception&) {
    n = -1;  // a garbage length field can make the generated code throw length_error
  }
  if (n < 0) {
    Fail(origin + ": " + std::to_string(data.size()) + " bytes are not a valid romo_lcm." +
         Msg::getTypeName() + " message");
  }
  return msg;
}

romo_lcm::image_t EncodeImage(const CameraFrame& frame, ImageEncoding encoding) {
  const Image& image = frame.image;
  image.Validate();
  romo_lcm::image_t msg;
  msg.stamp_ns = frame.stamp_ns;
  msg.sequence = static_cast<std::int64_t>(frame.sequence);
  msg.camera_id = frame.camera_id;
  msg.width = image.width;
  msg.height = image.height;
  msg.pixel_format = static_cast<std::int8_t>(image.format);
  msg.encoding = static_cast<std::int8_t>(encoding);
  const int row_bytes = image.width * BytesPerPixel(image.format);
  if (encoding == ImageEncoding::kRaw || image.empty()) {
    msg.encoding = static_cast<std::int8_t>(ImageEncoding::kRaw);
    // Stored packed: padding between rows is not worth recording.
    msg.stride = row_bytes;
    msg.data.resize(static_cast<std::size_t>(row_bytes) * image.height);
    for (int y = 0; y < image.height; ++y) {
      std::memcpy(msg.data.data() + static_cast<std::size_t>(y) * row_bytes, image.row(y),
                  static_cast<std::size_t>(row_bytes));
    }
  } else {
    const int type = image.format == PixelFormat::kMono8    ? CV_8UC1
                     : image.format == PixelFormat::kMono16 ? CV_16UC1
                                                            : CV_8UC3;
    cv::Mat view(image.height, image.width, type, const_cast<std::uint8_t*>(image.data.data()),
                 static_cast<std::size_t>(image.stride_bytes));
    cv::Mat bgr;
    if (image.format == PixelFormat::kRgb8) {
      // PNG files hold RGB; OpenCV writes BGR Mats as RGB, so hand it BGR.
      bgr.create(image.height, image.width, CV_8UC3);
      for (int y = 0; y < image.height; ++y) {
        const std::uint8_t* src = view.ptr<std::uint8_t>(y);
        std::uint8_t* dst = bgr.ptr<std::uint8_t>(y);
        for (int x = 0; x < image.width; ++x) {
          dst[3 * x] = src[3 * x + 2];
          dst[3 * x + 1] = src[3 * x + 1];
          dst[3 * x + 2] = src[3 * x];
        }
      }
      view = bgr;
    }
    // Level 1: most of PNG's gain at a fraction of the time of the default level.
    ROMO_DEMAND(cv::imencode(".png", view, msg.data, {cv::IMWRITE_PNG_COMPRESSION, 1}));
    msg.stride = row_bytes;
  }
  msg.size = static_cast<std::int32_t>(msg.data.size());
  return msg;
}

CameraFrame DecodeImage(const romo_lcm::image_t& msg, const std::string& origin) {
  CameraFrame frame;
  frame.stamp_ns = msg.stamp_ns;
  frame.sequence = static_cast<std::uint64_t>(msg.sequence);
  frame.camera_id = msg.camera_id;
  if (msg.pixel_format < 0 || msg.pixel_format > 2) {
    Fail(origin + ": image pixel_format = " + std::to_string(msg.pixel_format) +
         " (0 mono8, 1 mono16, 2 rgb8)");
  }
  const auto format = static_cast<PixelFormat>(msg.pixel_format);
  if (msg.width < 0 || msg.height < 0 || msg.width > 65535 || msg.height > 65535) {
    Fail(origin + ": image size " + std::to_string(msg.width) + "x" + std::to_string(msg.height) +
         " is implausible");
  }
  if (msg.width == 0 || msg.height == 0) {
    frame.image.format = format;
    return frame;
  }
  Image& image = frame.image;
  if (msg.encoding == static_cast<std::int8_t>(ImageEncoding::kRaw)) {
    const int row_bytes = msg.width * BytesPerPixel(format);
    if (msg.stride < row_bytes ||
        static_cast<std::int64_t>(msg.stride) * (msg.height - 1) + row_bytes > msg.size) {
      Fail(origin + ": raw image " + std::to_string(msg.width) + "x" + std::to_string(msg.height) +
           " stride " + std::to_string(msg.stride) + " does not fit its " +
           std::to_string(msg.size) + " bytes");
    }
    image = Image::Allocate(format, msg.width, msg.height);
    for (int y = 0; y < msg.height; ++y) {
      std::memcpy(image.row(y), msg.data.data() + static_cast<std::size_t>(y) * msg.stride,
                  static_cast<std::size_t>(row_bytes));
    }
  } else if (msg.encoding == static_cast<std::int8_t>(ImageEncoding::kPng)) {
    cv::Mat decoded;
    try {
      decoded = cv::imdecode(msg.data, cv::IMREAD_UNCHANGED);
    } catch (const cv::Exception&) {
      decoded.release();
    }
    const int want = format == PixelFormat::kMono8    ? CV_8UC1
                     : format == PixelFormat::kMono16 ? CV_16UC1
                                                      : CV_8UC3;
    if (decoded.empty() || decoded.type() != want || decoded.cols != msg.width ||
        decoded.rows != msg.height) {
      Fail(origin + ": PNG image does not decode to " + std::to_string(msg.width) + "x" +
           std::to_string(msg.height) + " " + ToString(format));
    }
    image = Image::Allocate(format, msg.width, msg.height);
    const int row_bytes = msg.width * BytesPerPixel(format);
    for (int y = 0; y < msg.height; ++y) {
      const std::uint8_t* src = decoded.ptr<std::uint8_t>(y);
      std::uint8_t* dst = image.row(y);
      if (format == PixelFormat::kRgb8) {
        for (int x = 0; x < msg.width; ++x) {
          dst[3 * x] = src[3 * x + 2];
          dst[3 * x + 1] = src[3 * x + 1];
          dst[3 * x + 2] = src[3 * x];
        }
      } else {
        std::memcpy(dst, src, static_cast<std::size_t>(row_bytes));
      }
    }
  } else {
    Fail(origin + ": image encoding = " + std::to_string(msg.encoding) + " (0 raw, 1 png)");
  }
  return frame;
}

std::uint32_t BigEndian32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         std::uint32_t{p[3]};
}

std::int64_t BigEndian64(const std::uint8_t* p) {
  return static_cast<std::int64_t>((std::uint64_t{BigEndian32(p)} << 32) | BigEndian32(p + 4));
}

}  // namespace

std::vector<std::uint8_t> EncodeStereo(const StereoFrame& frame, std::int64_t set_stamp_ns,
                                       std::uint64_t set_sequence, ImageEncoding encoding) {
  romo_lcm::stereo_frame_t msg;
  msg.stamp_ns = set_stamp_ns;
  msg.frame_sequence = static_cast<std::int64_t>(set_sequence);
  msg.rig_id = frame.rig_id;
  msg.left = EncodeImage(frame.left, encoding);
  msg.right = EncodeImage(frame.right, encoding);
  return Encode(msg);
}

std::vector<std::uint8_t> EncodeRgbd(const RgbdFrame& frame, std::uint64_t set_sequence,
                                     ImageEncoding encoding) {
  romo_lcm::rgbd_frame_t msg;
  msg.stamp_ns = frame.stamp_ns;
  msg.frame_sequence = static_cast<std::int64_t>(set_sequence);
  msg.depth_scale_m = frame.depth_scale_m;
  CameraFrame rgb{frame.rgb, frame.stamp_ns, frame.sequence, "rgb"};
  CameraFrame depth{frame.depth, frame.stamp_ns, frame.sequence, "depth"};
  msg.rgb = EncodeImage(rgb, encoding);
  msg.depth = EncodeImage(depth, encoding);
  return Encode(msg);
}

std::vector<std::uint8_t> EncodeVehicleState(const VehicleState& state,
                                             std::uint64_t set_sequence) {
  romo_lcm::vehicle_state_t msg;
  msg.stamp_ns = state.stamp_ns;
  msg.frame_sequence = static_cast<std::int64_t>(set_sequence);
  const Eigen::Vector3d t = state.T_world_vehicle.translation();
  const Eigen::Quaterniond q(state.T_world_vehicle.linear());
  for (int i = 0; i < 3; ++i) msg.position_m[i] = t[i];
  msg.orientation_wxyz[0] = q.w();
  msg.orientation_wxyz[1] = q.x();
  msg.orientation_wxyz[2] = q.y();
  msg.orientation_wxyz[3] = q.z();
  msg.speed_mps = state.speed_mps;
  msg.yaw_rate_radps = state.yaw_rate_radps;
  return Encode(msg);
}

std::vector<std::uint8_t> EncodeGnss(const GnssFix& fix, std::uint64_t set_sequence) {
  romo_lcm::gnss_fix_t msg;
  msg.stamp_ns = fix.stamp_ns;
  msg.frame_sequence = static_cast<std::int64_t>(set_sequence);
  msg.latitude_deg = fix.latitude_deg;
  msg.longitude_deg = fix.longitude_deg;
  msg.altitude_m = fix.altitude_m;
  msg.horizontal_sigma_m = fix.horizontal_sigma_m;
  msg.valid = fix.valid;
  return Encode(msg);
}

std::vector<std::uint8_t> EncodeCalibration(const std::string& yaml, std::int64_t stamp_ns) {
  romo_lcm::calibration_t msg;
  msg.stamp_ns = stamp_ns;
  msg.yaml = yaml;
  return Encode(msg);
}

StereoFrame DecodeStereo(const std::vector<std::uint8_t>& data, const std::string& origin,
                         std::int64_t* set_stamp_ns, std::uint64_t* set_sequence) {
  CheckImageCounts(data, romo_lcm::stereo_frame_t::getHash(), 8 + 8 + 4, "stereo_frame_t", origin);
  const auto msg = Decode<romo_lcm::stereo_frame_t>(data, origin);
  StereoFrame frame;
  frame.rig_id = msg.rig_id;
  frame.left = DecodeImage(msg.left, origin + " left");
  frame.right = DecodeImage(msg.right, origin + " right");
  *set_stamp_ns = msg.stamp_ns;
  *set_sequence = static_cast<std::uint64_t>(msg.frame_sequence);
  return frame;
}

RgbdFrame DecodeRgbd(const std::vector<std::uint8_t>& data, const std::string& origin,
                     std::uint64_t* set_sequence) {
  CheckImageCounts(data, romo_lcm::rgbd_frame_t::getHash(), 8 + 8 + 8, "rgbd_frame_t", origin);
  const auto msg = Decode<romo_lcm::rgbd_frame_t>(data, origin);
  RgbdFrame frame;
  CameraFrame rgb = DecodeImage(msg.rgb, origin + " rgb");
  CameraFrame depth = DecodeImage(msg.depth, origin + " depth");
  frame.rgb = std::move(rgb.image);
  frame.depth = std::move(depth.image);
  frame.depth_scale_m = msg.depth_scale_m;
  frame.stamp_ns = msg.stamp_ns;
  frame.sequence = rgb.sequence;
  *set_sequence = static_cast<std::uint64_t>(msg.frame_sequence);
  return frame;
}

VehicleState DecodeVehicleState(const std::vector<std::uint8_t>& data, const std::string& origin,
                                std::uint64_t* set_sequence) {
  const auto msg = Decode<romo_lcm::vehicle_state_t>(data, origin);
  VehicleState state;
  state.stamp_ns = msg.stamp_ns;
  Eigen::Quaterniond q(msg.orientation_wxyz[0], msg.orientation_wxyz[1], msg.orientation_wxyz[2],
                       msg.orientation_wxyz[3]);
  if (!(q.norm() > 0.5)) Fail(origin + ": vehicle_state_t orientation is not a rotation");
  state.T_world_vehicle = Eigen::Isometry3d::Identity();
  state.T_world_vehicle.linear() = q.normalized().toRotationMatrix();
  state.T_world_vehicle.translation() =
      Eigen::Vector3d(msg.position_m[0], msg.position_m[1], msg.position_m[2]);
  state.speed_mps = msg.speed_mps;
  state.yaw_rate_radps = msg.yaw_rate_radps;
  *set_sequence = static_cast<std::uint64_t>(msg.frame_sequence);
  return state;
}

GnssFix DecodeGnss(const std::vector<std::uint8_t>& data, const std::string& origin,
                   std::uint64_t* set_sequence) {
  const auto msg = Decode<romo_lcm::gnss_fix_t>(data, origin);
  GnssFix fix;
  fix.stamp_ns = msg.stamp_ns;
  fix.latitude_deg = msg.latitude_deg;
  fix.longitude_deg = msg.longitude_deg;
  fix.altitude_m = msg.altitude_m;
  fix.horizontal_sigma_m = msg.horizontal_sigma_m;
  fix.valid = msg.valid;
  // A fix said valid is used for the ENU origin and the WGS84 outputs: it must be a position.
  if (fix.valid && !(std::abs(fix.latitude_deg) <= 90.0 && std::abs(fix.longitude_deg) <= 180.0 &&
                     std::isfinite(fix.altitude_m) && fix.horizontal_sigma_m >= 0.0)) {
    std::ostringstream what;
    what << origin << ": gnss_fix_t is not a position: latitude " << fix.latitude_deg << " deg, longitude "
         << fix.longitude_deg << " deg, altitude " << fix.altitude_m << " m, sigma " << fix.horizontal_sigma_m << " m";
    Fail(what.str());
  }
  *set_sequence = static_cast<std::uint64_t>(msg.frame_sequence);
  return fix;
}

std::string DecodeCalibration(const std::vector<std::uint8_t>& data, const std::string& origin) {
  return Decode<romo_lcm::calibration_t>(data, origin).yaml;
}

EventFileReader::EventFileReader(const std::string& path) : path_(path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) Fail(path + ": recording not found");
  if (!S_ISREG(st.st_mode)) Fail(path + ": not a regular file");
  file_ = std::fopen(path.c_str(), "rb");
  if (file_ == nullptr) Fail(path + ": cannot open recording");
  file_size_ = static_cast<std::int64_t>(st.st_size);
}

EventFileReader::~EventFileReader() {
  if (file_ != nullptr) std::fclose(file_);
}

void EventFileReader::SeekTo(std::int64_t offset) {
  ROMO_THROW_UNLESS(offset >= 0);
  std::fseek(file_, static_cast<long>(offset), SEEK_SET);
  offset_ = offset;
}

ReadResult EventFileReader::Damaged(ReadResult result, const char* why) {
  std::fseek(file_, static_cast<long>(offset_), SEEK_SET);
  damage_ = why;
  return result;
}

ReadResult EventFileReader::Next(LogEvent* event) {
  std::uint8_t header[kEventHeaderBytes];
  const std::size_t got = std::fread(header, 1, sizeof header, file_);
  if (got == 0 && std::feof(file_)) return ReadResult::kEnd;
  if (got < 4) return Damaged(ReadResult::kTruncated, "event header cut short");
  if (BigEndian32(header) != kLogSyncWord) {
    return Damaged(ReadResult::kCorrupt, "no event sync word 0xEDA1DA01");
  }
  if (got < sizeof header) return Damaged(ReadResult::kTruncated, "event header cut short");
  const std::int64_t timestamp = BigEndian64(header + 12);
  const auto channel_len = static_cast<std::int32_t>(BigEndian32(header + 20));
  const auto data_len = static_cast<std::int32_t>(BigEndian32(header + 24));
  if (channel_len <= 0 || channel_len > kMaxChannelBytes || data_len < 0 ||
      data_len > kMaxEventBytes) {
    return Damaged(ReadResult::kCorrupt, "impossible channel or data length in an event header");
  }
  // Event times are microseconds since 1970 and readers turn them into int64 nanoseconds:
  // a negative one or one past year 2262 is a damaged header, not a time.
  if (timestamp < 0 || timestamp > kMaxTimestampUs) {
    return Damaged(ReadResult::kCorrupt, "event time outside 1970..2262");
  }
  // The lengths come from the file: one past its end means a cut (or damaged) event, reported
  // without allocating what the header claims (up to 1 GiB for a few bytes of input).
  struct stat st {};
  const std::int64_t size_now =
      ::fstat(::fileno(file_), &st) == 0 ? static_cast<std::int64_t>(st.st_size) : file_size_;
  if (offset_ + kEventHeaderBytes + channel_len + data_len > size_now) {
    return Damaged(ReadResult::kTruncated, "event runs past the end of the file");
  }
  event->channel.resize(static_cast<std::size_t>(channel_len));
  event->data.resize(static_cast<std::size_t>(data_len));
  if (std::fread(event->channel.data(), 1, event->channel.size(), file_) != event->channel.size() ||
      std::fread(event->data.data(), 1, event->data.size(), file_) != event->data.size()) {
    return Damaged(ReadResult::kTruncated, "event runs past the end of the file");
  }
  event->timestamp_us = timestamp;
  offset_ += kEventHeaderBytes + channel_len + data_len;
  return ReadResult::kEvent;
}

}  // namespace romo::drivers::lcm_codec

namespace romo::drivers {

std::vector<std::uint8_t> EncodeGnssMessage(const GnssFix& fix) { return lcm_codec::EncodeGnss(fix, 0); }

GnssFix DecodeGnssMessage(const std::uint8_t* data, std::size_t size, const std::string& origin) {
  std::uint64_t sequence = 0;
  return lcm_codec::DecodeGnss(std::vector<std::uint8_t>(data, data + size), origin, &sequence);
}

}  // namespace romo::drivers
