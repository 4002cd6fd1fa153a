#pragma once
// Little-endian encoding byte by byte, so that files mean the same on any host byte order.

#include <bit>
#include <concepts>
#include <cstdint>
#include <string>
#include <type_traits>

namespace mvflow::io {

//! Integers and doubles, the types binary formats hold.
template <typename T>
concept LittleEndianValue = std::integral<T> || std::same_as<T, double>;

//! Appends \p value to \p bytes, least significant byte first.
template <LittleEndianValue T>
void append_little_endian(std::string& bytes, T value) {
  std::uint64_t bits = 0;
  if constexpr (std::same_as<T, double>) {
    bits = std::bit_cast<std::uint64_t>(value);
  } else {
    bits = static_cast<std::make_unsigned_t<T>>(value);
  }
  for (std::size_t i = 0; i < sizeof(T); ++i) bytes.push_back(static_cast<char>((bits >> (8 * i)) & 0xffu));
}

//! The value whose sizeof(T) bytes start at \p bytes, least significant byte first.
template <LittleEndianValue T>
T decode_little_endian(const unsigned char* bytes) {
  std::uint64_t bits = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i) bits |= static_cast<std::uint64_t>(bytes[i]) << (8 * i);
  if constexpr (std::same_as<T, double>) {
    return std::bit_cast<double>(bits);
  } else {
    // Two's complement (guaranteed since C++20) makes the narrowing exact for signed types.
    return static_cast<T>(static_cast<std::make_unsigned_t<T>>(bits));
  }
}

}  // namespace mvflow::io
