#pragma once
// Numbers as text in their shortest form that reads back to the same value, so that every
// text writer's write → read round trip is exact.

#include <array>
#include <charconv>
#include <string>

namespace mvflow::io {

template <typename T>
void append_number(std::string& text, T value) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  text.append(buffer.data(), result.ptr);
}

template <typename T>
std::string format_number(T value) {
  std::string text;
  append_number(text, value);
  return text;
}

}  // namespace mvflow::io
