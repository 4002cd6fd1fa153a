#include "io/binary_reader.h"

#include <cmath>

#include "engine/model/error.h"
#include "io/number_text.h"

namespace mvflow::io {

BinaryReader::BinaryReader(std::filesystem::path file)
    : file_(std::move(file)), in_(file_, std::ios::binary) {
  if (!in_) throw IoError(file_, "cannot open for reading");
  std::error_code error;
  size_ = std::filesystem::file_size(file_, error);
  if (error) throw IoError(file_, "cannot read the file's size: " + error.message());
}

void BinaryReader::fail_at(std::uint64_t offset, const std::string& message) const {
  throw InputError(file_, 0, "byte " + std::to_string(offset) + ": " + message);
}

void BinaryReader::read_bytes(unsigned char* bytes, std::size_t count, const std::string& what,
                              const char* type) {
  const auto expected = [&] {
    return "expected " + what + " (" + type + ", " + std::to_string(count) + " bytes)";
  };
  if (size_ - offset_ < count) fail(expected() + ", the file ends at byte " + std::to_string(size_));
  // The size was checked above; a failing read means the file changed while being read.
  if (!in_.read(reinterpret_cast<char*>(bytes), static_cast<std::streamsize>(count)))
    fail(expected() + ", the file could not be read here (did it change while being read?)");
  offset_ += count;
}

double BinaryReader::read_finite(const std::string& what) {
  const std::uint64_t start = offset_;
  const double value = read<double>(what);
  if (!std::isfinite(value))
    fail_at(start, "expected a finite number for " + what + ", got " + format_number(value));
  return value;
}

std::string BinaryReader::read_null_terminated(const std::string& what) {
  const std::uint64_t start = offset_;
  std::string text;
  while (offset_ < size_) {
    const int c = in_.get();
    if (c == std::char_traits<char>::eof())
      fail("expected " + what + ", the file could not be read here (did it change while being read?)");
    ++offset_;
    if (c == 0) return text;
    text.push_back(static_cast<char>(c));
  }
  fail_at(start, "expected " + what + " ending in a NUL byte, the file ends at byte " +
                     std::to_string(size_) + " without one");
}

void BinaryReader::skip(std::uint64_t count, std::uint64_t record_size, const std::string& what) {
  // Division, not count × size: a huge count must not overflow into a small product.
  if (record_size != 0 && count > (size_ - offset_) / record_size)
    fail("expected " + std::to_string(count) + " " + what + " (" + std::to_string(record_size) +
         " bytes each), the file ends at byte " + std::to_string(size_));
  const std::uint64_t bytes = count * record_size;
  in_.seekg(static_cast<std::streamoff>(offset_ + bytes));
  if (!in_) fail("expected " + what + ", the file could not be read here (did it change while being read?)");
  offset_ += bytes;
}

void BinaryReader::check_count(std::uint64_t count, std::uint64_t min_record_size, std::uint64_t count_offset,
                               const std::string& what) const {
  MVFLOW_CHECK(min_record_size > 0, "BinaryReader::check_count: records have at least one byte");
  const std::uint64_t left = size_ - offset_;
  if (count > left / min_record_size)
    fail_at(count_offset, "expected " + what + ", got " + std::to_string(count) +
                              ", but the file ends at byte " + std::to_string(size_) + ": the " +
                              std::to_string(left) + " bytes left hold at most " +
                              std::to_string(left / min_record_size) + " (" +
                              std::to_string(min_record_size) + " bytes each at least)");
}

void BinaryReader::expect_end(const std::string& what) const {
  if (offset_ != size_)
    fail("expected the end of the file after " + what + ", found " + std::to_string(size_ - offset_) +
         " more bytes");
}

}  // namespace mvflow::io
