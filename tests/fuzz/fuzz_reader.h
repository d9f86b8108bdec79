// The fuzz input read front to back as small values, for the targets that decode it into a sequence
// of requests: a seed can then be written by hand, field after field. Reads past the end give
// zeros and empty strings, so every input decodes into something and its end is a clean end.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

namespace deform::fuzz {

class FuzzReader {
 public:
  FuzzReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  bool empty() const { return position_ >= size_; }

  std::uint8_t Byte() { return empty() ? 0 : data_[position_++]; }

  std::uint32_t U32() {
    std::uint32_t value = 0;
    for (int i = 0; i < 4; ++i) value |= static_cast<std::uint32_t>(Byte()) << (8 * i);
    return value;
  }

  std::uint64_t U64() { return U32() | static_cast<std::uint64_t>(U32()) << 32; }

  // A byte-length-prefixed string (up to 255 bytes).
  std::string ShortString() { return Bytes(Byte()); }

  // `count` bytes, fewer at the end of the input.
  std::string Bytes(std::size_t count) {
    const std::size_t available = empty() ? 0 : size_ - position_;
    const std::size_t taken = count < available ? count : available;
    std::string bytes(reinterpret_cast<const char*>(data_ + position_), taken);
    position_ += taken;
    return bytes;
  }

  // A double chosen by one byte: 0xf0-0xf7 values that probe the checks (NaN, infinities, the
  // largest double, a denormal, 1e9, 1e-9, 0.5), 0xf8-0xfe hundredths (0.01 .. 0.07), 0xff the next
  // 8 bytes as raw bits, any other byte itself as a signed integer (-128 .. -17, 0 .. 127).
  double Double() {
    const std::uint8_t choice = Byte();
    switch (choice) {
      case 0xf0:
        return std::numeric_limits<double>::quiet_NaN();
      case 0xf1:
        return std::numeric_limits<double>::infinity();
      case 0xf2:
        return -std::numeric_limits<double>::infinity();
      case 0xf3:
        return std::numeric_limits<double>::max();
      case 0xf4:
        return std::numeric_limits<double>::denorm_min();
      case 0xf5:
        return 1e9;
      case 0xf6:
        return 1e-9;
      case 0xf7:
        return 0.5;
      case 0xff: {
        const std::uint64_t bits = U64();
        double value;
        std::memcpy(&value, &bits, sizeof(value));
        return value;
      }
      default:
        if (choice >= 0xf8) return (choice - 0xf7) * 0.01;
        return static_cast<double>(static_cast<std::int8_t>(choice));
    }
  }

 private:
  const std::uint8_t* const data_;
  const std::size_t size_;
  std::size_t position_ = 0;
};

}  // namespace deform::fuzz
