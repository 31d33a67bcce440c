#pragma once
/// Bounds-checks an LCM encoding before decoding it. LCM's generated decoders size each array
/// from the count in the message before checking that the bytes are there, so a corrupt count in
/// a few bytes of input asks for gigabytes (or, negative, throws std::length_error). A decoder
/// walks the message first: every count must fit the bytes that are left.
#include <cstddef>
#include <cstdint>
#include <string>

namespace romo::drivers {

class LcmWalker {
 public:
  LcmWalker(const void* data, std::size_t size)
      : bytes_(static_cast<const std::uint8_t*>(data)), size_(data == nullptr ? 0 : size) {}

  /// Skips @p n bytes of fixed-size fields; false (and the walk fails) when fewer are left.
  bool Skip(std::size_t n) {
    if (!ok_ || n > size_ - pos_) return ok_ = false;
    pos_ += n;
    return true;
  }
  /// Reads an int32 count of elements of at least @p min_bytes_each bytes; false when it is
  /// negative or the elements cannot fit the rest of the message.
  bool Count(std::size_t min_bytes_each, std::int32_t* count, const char* field) {
    if (!ok_ || 4 > size_ - pos_) return ok_ = false;
    const std::uint8_t* p = bytes_ + pos_;
    const auto v = static_cast<std::int32_t>((std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) |
                                             (std::uint32_t{p[2]} << 8) | std::uint32_t{p[3]});
    pos_ += 4;
    if (v < 0 || static_cast<std::uint64_t>(v) * min_bytes_each > size_ - pos_) {
      bad_field_ = field;
      bad_value_ = v;
      return ok_ = false;
    }
    *count = v;
    return true;
  }
  /// Skips an LCM string (int32 length including the terminating NUL, then the bytes).
  bool String(const char* field) {
    std::int32_t length = 0;
    if (!Count(1, &length, field)) return false;
    if (length == 0) {  // LCM writes at least the NUL; the generated decoder cannot take 0
      bad_field_ = field;
      return ok_ = false;
    }
    // A NUL inside the text: the decoded std::string would keep it, but LCM encodes strings up
    // to their first NUL, so the message would not encode back to its own size.
    for (std::int32_t i = 0; i + 1 < length; ++i) {
      if (bytes_[pos_ + static_cast<std::size_t>(i)] == 0) {
        bad_field_ = field;
        bad_value_ = i;
        embedded_nul_ = true;
        return ok_ = false;
      }
    }
    return Skip(static_cast<std::size_t>(length));
  }
  /// Counts of elements of @p bytes_each fixed bytes: the count, then skips the elements.
  bool FixedArray(std::size_t bytes_each, const char* field) {
    std::int32_t n = 0;
    return Count(bytes_each, &n, field) && Skip(bytes_each * static_cast<std::size_t>(n));
  }

  bool ok() const { return ok_; }
  /// Why the walk failed, naming @p type: the field and its count, or truncation.
  std::string Reason(const std::string& type) const {
    if (embedded_nul_) {
      return type + "." + bad_field_ + ": NUL at byte " + std::to_string(bad_value_) + " inside the text";
    }
    if (bad_field_ != nullptr) {
      return type + "." + bad_field_ + " = " + std::to_string(bad_value_) + " does not fit a " +
             std::to_string(size_) + "-byte message";
    }
    return type + ": truncated (" + std::to_string(size_) + " bytes)";
  }

 private:
  const std::uint8_t* bytes_;
  std::size_t size_;
  std::size_t pos_ = 0;
  bool ok_ = true;
  const char* bad_field_ = nullptr;
  std::int32_t bad_value_ = 0;
  bool embedded_nul_ = false;
};

/// True when @p data starts with the 8-byte LCM type hash @p hash (big-endian).
inline bool LcmHashMatches(const void* data, std::size_t size, std::int64_t hash) {
  if (data == nullptr || size < 8) return false;
  const auto* p = static_cast<const std::uint8_t*>(data);
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | p[i];
  return static_cast<std::int64_t>(v) == hash;
}

}  // namespace romo::drivers
