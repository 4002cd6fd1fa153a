#include "io/text_reader.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>

#include "engine/model/error.h"

namespace mvflow::io {

TextReader::TextReader(std::filesystem::path file) : file_(std::move(file)), in_(file_, std::ios::binary) {
  if (!in_) throw IoError(file_, "cannot open for reading");
}

bool TextReader::next_line() {
  if (!std::getline(in_, line_)) return false;
  ++line_number_;
  if (!line_.empty() && line_.back() == '\r') line_.pop_back();
  return true;
}

bool TextReader::next_content_line(char comment) {
  while (next_line()) {
    // The whitespace of split_whitespace (std::isspace): a line of a lone '\r' is blank too, not a
    // content line with no token.
    const auto first = line_.find_first_not_of(" \t\n\v\f\r");
    if (first == std::string::npos) continue;
    if (comment != 0 && line_[first] == comment) continue;
    return true;
  }
  return false;
}

void TextReader::require_content_line(const std::string& what, char comment) {
  if (!next_content_line(comment))
    throw InputError(file_, line_number_ + 1, "unexpected end of file, expected " + what);
}

void TextReader::fail(const std::string& message) const { throw InputError(file_, line_number_, message); }

std::vector<std::string_view> split_whitespace(std::string_view text) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    const std::size_t start = i;
    while (i < text.size() && !std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    if (i > start) tokens.push_back(text.substr(start, i - start));
  }
  return tokens;
}

double parse_double(const TextReader& reader, std::string_view token, const std::string& what) {
  double value = 0.0;
  const char* begin = token.data();
  const char* end = begin + token.size();
  if (!token.empty() && *begin == '+') ++begin;  // from_chars rejects a leading '+'
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  if (ec != std::errc() || ptr != end || token.empty())
    reader.fail("expected a number for " + what + ", got '" + std::string(token) + "'");
  if (!std::isfinite(value))
    reader.fail("expected a finite number for " + what + ", got '" + std::string(token) + "'");
  return value;
}

long long parse_integer(const TextReader& reader, std::string_view token, const std::string& what) {
  long long value = 0;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc() || ptr != token.data() + token.size() || token.empty())
    reader.fail("expected an integer for " + what + ", got '" + std::string(token) + "'");
  if (value < 0) reader.fail("expected a non-negative integer for " + what + ", got '" + std::string(token) + "'");
  return value;
}

std::size_t reservable(std::size_t count, const std::filesystem::path& file, std::size_t min_bytes) {
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(file, error);
  if (error) return 0;
  return static_cast<std::size_t>(std::min<std::uintmax_t>(count, size / std::max<std::size_t>(min_bytes, 1)));
}

}  // namespace mvflow::io
