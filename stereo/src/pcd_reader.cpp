// LoadPcd: a PCD reader of our own (ascii, binary, binary_compressed). PCL's reader trusts its
// input: it sizes buffers from the header alone (10^14-byte fields in a 150-byte file), reads a
// line by its first token's prefix, lets a second FIELDS line resize the fields after SIZE set
// their offsets, and corrupted its heap on inputs fuzz_pcd found (ASan: bad frees, a broken
// quarantine) that no single input reproduced. Here every size is checked before it is used.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "romo/core/check.hpp"
#include "romo/stereo/pcd_io.hpp"

namespace romo::stereo {
namespace {

struct Field {
  std::string name;
  char type = 'F';         // I, U or F
  std::size_t size = 4;    // bytes of one element
  std::size_t count = 1;   // elements
  std::size_t offset = 0;   // bytes into a packed point (binary, binary_compressed)
  std::size_t element = 0;  // values into an ascii point line
};

struct Header {
  std::vector<Field> fields;
  std::size_t width = 0, height = 1, points = 0, point_step = 0, values_per_point = 0;
  std::string data;  // ascii, binary or binary_compressed
  std::size_t data_offset = 0;  // first byte after the DATA line
  int data_line = 0;
};

[[noreturn]] void FailAt(const std::string& path, int line, const std::string& what) {
  Fail("PCD file '" + path + "' line " + std::to_string(line) + ": " + what);
}

// Counts (WIDTH, SIZE, ...) are plain decimal integers of at most 12 digits: no sign, no overflow.
std::size_t Count(const std::string& token, const std::string& path, int line, const std::string& key) {
  if (token.empty() || token.size() > 12 || token.find_first_not_of("0123456789") != std::string::npos) {
    FailAt(path, line, key + " value '" + token.substr(0, 24) + "' is not a count of a sane size");
  }
  return static_cast<std::size_t>(std::stoull(token));
}

Header ParseHeader(const std::string& bytes, const std::string& path) {
  Header h;
  std::map<std::string, int> seen_at;
  std::vector<std::string> sizes, types, counts;
  std::size_t pos = 0;
  int line_number = 0;
  while (h.data.empty()) {
    if (pos >= bytes.size() || pos > (1u << 20)) Fail("PCD file '" + path + "': no DATA line: not a PCD file?");
    const std::size_t end = bytes.find('\n', pos);
    const std::string line = bytes.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
    pos = end == std::string::npos ? bytes.size() : end + 1;
    ++line_number;
    std::istringstream in(line);
    std::string key;
    if (!(in >> key) || key[0] == '#') continue;
    std::vector<std::string> values;
    for (std::string v; in >> v;) values.push_back(v);
    if (key == "COLUMNS") key = "FIELDS";  // the PCD 0.5 name
    static const char* const kKeys[] = {"VERSION", "FIELDS", "SIZE",   "TYPE", "COUNT",
                                        "WIDTH",   "HEIGHT", "VIEWPOINT", "POINTS", "DATA"};
    bool known = false;
    for (const char* k : kKeys) known = known || key == k;
    if (!known) FailAt(path, line_number, "unknown header keyword '" + key.substr(0, 24) + "': not a PCD file?");
    const auto [first, fresh] = seen_at.emplace(key, line_number);
    if (!fresh) {
      FailAt(path, line_number, "a second " + key + " line (the first is line " + std::to_string(first->second) + ")");
    }
    const bool per_field = key == "SIZE" || key == "TYPE" || key == "COUNT";
    if (per_field && !seen_at.count("FIELDS")) FailAt(path, line_number, key + " before FIELDS");
    if (per_field && values.size() != h.fields.size()) {
      FailAt(path, line_number, key + " has " + std::to_string(values.size()) + " entries for " +
                                    std::to_string(h.fields.size()) + " FIELDS");
    }
    if (key == "FIELDS") {
      if (values.empty()) FailAt(path, line_number, "FIELDS names no field");
      for (const auto& name : values) h.fields.push_back(Field{name});
    } else if (key == "SIZE") {
      sizes = values;
    } else if (key == "TYPE") {
      types = values;
    } else if (key == "COUNT") {
      counts = values;
    } else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
      if (values.size() != 1) FailAt(path, line_number, key + " needs one value");
      (key == "WIDTH" ? h.width : key == "HEIGHT" ? h.height : h.points) = Count(values[0], path, line_number, key);
    } else if (key == "DATA") {
      if (values.size() != 1 || (values[0] != "ascii" && values[0] != "binary" && values[0] != "binary_compressed")) {
        FailAt(path, line_number, "DATA must be ascii, binary or binary_compressed");
      }
      h.data = values[0];
      h.data_offset = pos;
      h.data_line = line_number;
    }
  }
  for (const char* required : {"FIELDS", "SIZE", "TYPE", "WIDTH"}) {
    if (!seen_at.count(required)) Fail("PCD file '" + path + "' has no " + required + " line");
  }
  for (std::size_t k = 0; k < h.fields.size(); ++k) {
    Field& f = h.fields[k];
    f.size = Count(sizes[k], path, seen_at["SIZE"], "SIZE");
    f.count = counts.empty() ? 1 : Count(counts[k], path, seen_at["COUNT"], "COUNT");
    if (types[k].size() != 1 || std::string("IUF").find(types[k][0]) == std::string::npos) {
      FailAt(path, seen_at["TYPE"], "TYPE '" + types[k].substr(0, 8) + "' of field '" + f.name + "' is not I, U or F");
    }
    f.type = types[k][0];
    const bool size_ok = f.type == 'F' ? (f.size == 4 || f.size == 8)
                                       : (f.size == 1 || f.size == 2 || f.size == 4 || f.size == 8);
    if (!size_ok) {
      FailAt(path, seen_at["SIZE"], "SIZE " + std::to_string(f.size) + " of field '" + f.name + "' (TYPE " + f.type +
                                        ") is not 1, 2, 4 or 8 bytes (4 or 8 for F)");
    }
    if (f.count == 0 || f.count > 4096) {
      FailAt(path, seen_at["COUNT"], "COUNT " + std::to_string(f.count) + " of field '" + f.name + "' is not 1..4096");
    }
    f.offset = h.point_step;  // both sums stay below 4096 x 8 x fields: no overflow
    f.element = h.values_per_point;
    h.point_step += f.size * f.count;
    h.values_per_point += f.count;
  }
  if (seen_at.count("POINTS") && h.points != h.width * h.height) {
    FailAt(path, seen_at["POINTS"], "POINTS " + std::to_string(h.points) + " is not WIDTH x HEIGHT = " +
                                        std::to_string(h.width) + " x " + std::to_string(h.height));
  }
  h.points = h.width * h.height;  // each < 10^12: no overflow
  return h;
}

// liblzf's format (what PCL writes): a control byte below 32 starts a run of ctrl + 1 literals;
// otherwise the top three bits are a length (7 = more in the next byte) and the rest with the
// next byte a distance back into what was written.
bool LzfDecompress(const std::uint8_t* in, std::size_t in_size, std::uint8_t* out, std::size_t out_size) {
  std::size_t ip = 0, op = 0;
  while (ip < in_size) {
    const std::size_t ctrl = in[ip++];
    if (ctrl < 32) {
      const std::size_t run = ctrl + 1;
      if (ip + run > in_size || op + run > out_size) return false;
      std::memcpy(out + op, in + ip, run);
      ip += run;
      op += run;
      continue;
    }
    std::size_t length = ctrl >> 5;
    if (length == 7) {
      if (ip >= in_size) return false;
      length += in[ip++];
    }
    length += 2;
    if (ip >= in_size) return false;
    const std::size_t back = ((ctrl & 0x1f) << 8) + in[ip++] + 1;
    if (back > op || op + length > out_size) return false;
    for (std::size_t k = 0; k < length; ++k, ++op) out[op] = out[op - back];  // may overlap
  }
  return op == out_size;
}

template <typename T>
double As(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return static_cast<double>(v);
}

double Value(const Field& f, const std::uint8_t* p) {
  if (f.type == 'F') return f.size == 4 ? As<float>(p) : As<double>(p);
  if (f.type == 'I') {
    switch (f.size) {
      case 1: return As<std::int8_t>(p);
      case 2: return As<std::int16_t>(p);
      case 4: return As<std::int32_t>(p);
      default: return As<std::int64_t>(p);
    }
  }
  switch (f.size) {
    case 1: return As<std::uint8_t>(p);
    case 2: return As<std::uint16_t>(p);
    case 4: return As<std::uint32_t>(p);
    default: return As<std::uint64_t>(p);
  }
}

// Values of point i's first element of each wanted field, as doubles: one accessor per layout.
class PointValues {
 public:
  virtual ~PointValues() = default;
  virtual double Get(std::size_t point, const Field& field) const = 0;
};

// binary: points packed one after another.
class PackedValues : public PointValues {
 public:
  PackedValues(const std::uint8_t* data, std::size_t step) : data_(data), step_(step) {}
  double Get(std::size_t point, const Field& f) const override { return Value(f, data_ + point * step_ + f.offset); }

 private:
  const std::uint8_t* data_;
  std::size_t step_;
};

// binary_compressed: each field's values for all points one after another.
class ColumnValues : public PointValues {
 public:
  ColumnValues(const std::uint8_t* data, std::size_t points) : data_(data), points_(points) {}
  double Get(std::size_t point, const Field& f) const override {
    return Value(f, data_ + f.offset * points_ + point * f.size * f.count);
  }

 private:
  const std::uint8_t* data_;
  std::size_t points_;
};

// ascii: every value parsed up front (nan and inf allowed, as PCL writes them).
class AsciiValues : public PointValues {
 public:
  AsciiValues(const std::string& bytes, const Header& h, const std::string& path) : per_point_(h.values_per_point) {
    values_.reserve(h.points * per_point_);
    std::size_t pos = h.data_offset;
    int line = h.data_line;
    for (std::size_t point = 0; point < h.points;) {
      if (pos >= bytes.size()) {
        Fail("PCD file '" + path + "' is truncated: " + std::to_string(point) + " of " + std::to_string(h.points) +
             " ascii points");
      }
      const std::size_t end = std::min(bytes.find('\n', pos), bytes.size());
      ++line;
      const std::string text = bytes.substr(pos, end - pos);
      pos = end + 1;
      if (text.find_first_not_of(" \t\r") == std::string::npos) continue;  // a blank line
      std::istringstream in(text);
      std::size_t got = 0;
      for (std::string token; in >> token; ++got) {
        char* stop = nullptr;
        const double v = std::strtod(token.c_str(), &stop);
        if (*stop != '\0' || got >= per_point_) break;
        values_.push_back(v);
      }
      if (got != per_point_ || values_.size() != (point + 1) * per_point_) {
        FailAt(path, line, "point " + std::to_string(point) + " does not have " + std::to_string(per_point_) +
                               " numbers");
      }
      ++point;
    }
  }
  double Get(std::size_t point, const Field& f) const override {
    return values_[point * per_point_ + f.element];
  }

 private:
  std::size_t per_point_;
  std::vector<double> values_;
};

const Field* FindField(const Header& h, const char* name) {
  for (const auto& f : h.fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

}  // namespace

PointCloud LoadPcd(const std::string& path, PcdLoadStats* stats) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    Fail("PCD file '" + path + "' does not exist or is not a regular file");
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) Fail("PCD file '" + path + "' cannot be opened");
  const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  const Header h = ParseHeader(bytes, path);
  const Field* fx = FindField(h, "x");
  const Field* fy = FindField(h, "y");
  const Field* fz = FindField(h, "z");
  for (const auto& [name, f] : {std::pair{"x", fx}, {"y", fy}, {"z", fz}}) {
    if (f == nullptr) Fail("PCD file '" + path + "': no field '" + name + "'");
  }
  const Field* fi = FindField(h, "intensity");
  const Field* fs = FindField(h, "sigma_z");
  const std::size_t n = h.points;
  const std::size_t available = bytes.size() - std::min(bytes.size(), h.data_offset);
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data()) + std::min(bytes.size(), h.data_offset);

  // Sizes are checked against the file before anything is allocated from them.
  std::vector<std::uint8_t> unpacked;
  std::unique_ptr<PointValues> values;
  const double claimed = static_cast<double>(n) * static_cast<double>(h.point_step);
  if (h.data == "binary") {
    if (claimed > static_cast<double>(available)) {
      Fail("PCD file '" + path + "' is truncated: binary data of " + std::to_string(n) + " points needs " +
           std::to_string(n * h.point_step) + " bytes after the header, found " + std::to_string(available));
    }
    values = std::make_unique<PackedValues>(data, h.point_step);
  } else if (h.data == "binary_compressed") {
    std::uint32_t sizes[2] = {0, 0};  // compressed, uncompressed
    if (available >= sizeof sizes) std::memcpy(sizes, data, sizeof sizes);
    // LZF turns 3 bytes into at most 264: a larger claim cannot be this file's.
    if (available < sizeof sizes || sizes[0] > available - sizeof sizes ||
        static_cast<double>(sizes[1]) != claimed || claimed > 100.0 * static_cast<double>(sizes[0]) + 4096.0) {
      Fail("PCD file '" + path + "' is truncated or corrupt: compressed block of " + std::to_string(sizes[0]) +
           " bytes (" + std::to_string(sizes[1]) + " uncompressed, expected " + std::to_string(n * h.point_step) +
           ") in a file of " + std::to_string(bytes.size()) + " bytes");
    }
    unpacked.resize(sizes[1]);
    if (!LzfDecompress(data + sizeof sizes, sizes[0], unpacked.data(), unpacked.size())) {
      Fail("PCD file '" + path + "' is corrupt: its LZF block does not decompress to " + std::to_string(sizes[1]) +
           " bytes");
    }
    values = std::make_unique<ColumnValues>(unpacked.data(), n);
  } else {
    // At least one digit and one separator per value.
    if (claimed > 0 && static_cast<double>(n) * static_cast<double>(h.values_per_point) * 2.0 >
                           static_cast<double>(available) + 1.0) {
      Fail("PCD file '" + path + "' header claims " + std::to_string(h.width) + " x " + std::to_string(h.height) +
           " points but the file has " + std::to_string(available) + " bytes of ascii data");
    }
    values = std::make_unique<AsciiValues>(bytes, h, path);
  }

  PointCloud cloud;
  cloud.Resize(n);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const float x = static_cast<float>(values->Get(i, *fx));
    const float y = static_cast<float>(values->Get(i, *fy));
    const float z = static_cast<float>(values->Get(i, *fz));
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) continue;
    const auto c = static_cast<Eigen::Index>(kept);
    cloud.xyz(0, c) = x;
    cloud.xyz(1, c) = y;
    cloud.xyz(2, c) = z;
    cloud.intensity[kept] = fi ? static_cast<float>(values->Get(i, *fi)) : 0.f;
    cloud.sigma_z_m[kept] = fs ? static_cast<float>(values->Get(i, *fs)) : 0.f;
    ++kept;
  }
  cloud.Resize(kept);
  if (stats != nullptr) {
    stats->points_in_file = n;
    stats->dropped_non_finite = n - kept;
    stats->had_intensity = fi != nullptr;
    stats->had_sigma_z = fs != nullptr;
  }
  return cloud;
}

}  // namespace romo::stereo
