#pragma once
// Sequential reading of little-endian binary formats with errors that name the file and the byte
// offset: "FILE: byte N: expected WHAT ...". Reads never go past the end of the file, and counts
// are checked against the bytes left before anything is allocated for them.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "io/little_endian.h"

namespace mvflow::io {

class BinaryReader {
 public:
  //! \throw IoError when the file cannot be opened or its size read.
  explicit BinaryReader(std::filesystem::path file);

  //! The next value, little-endian whatever the host's byte order. \throw InputError
  //! "byte N: expected WHAT (uint32, 4 bytes), the file ends at byte M" when fewer are left.
  template <LittleEndianValue T>
  T read(const std::string& what) {
    unsigned char bytes[sizeof(T)];
    read_bytes(bytes, sizeof(T), what, type_name<T>());
    return decode_little_endian<T>(bytes);
  }
  //! The next double, which must be finite. \throw InputError naming \p what and the value.
  double read_finite(const std::string& what);
  //! The bytes up to the next NUL byte, which is consumed. \throw InputError when none is left.
  std::string read_null_terminated(const std::string& what);
  //! Skips \p count records of \p record_size bytes. \throw InputError when fewer are left.
  void skip(std::uint64_t count, std::uint64_t record_size, const std::string& what);
  //! Checks that \p count records of at least \p min_record_size (> 0) bytes can follow; else throws
  //! "byte N: expected WHAT, got COUNT, but the file ends at byte M: ...", N being where the
  //! count was (\p count_offset). Call it before allocating anything for the records.
  void check_count(std::uint64_t count, std::uint64_t min_record_size, std::uint64_t count_offset,
                   const std::string& what) const;
  //! \throw InputError "byte N: expected the end of the file after WHAT, found K more bytes".
  void expect_end(const std::string& what) const;

  //! The offset of the next byte to read.
  std::uint64_t offset() const { return offset_; }
  std::uint64_t size() const { return size_; }
  const std::filesystem::path& file() const { return file_; }

  //! Throws InputError "FILE: byte OFFSET: message".
  [[noreturn]] void fail_at(std::uint64_t offset, const std::string& message) const;
  //! fail_at the current offset.
  [[noreturn]] void fail(const std::string& message) const { fail_at(offset_, message); }

 private:
  template <LittleEndianValue T>
  static const char* type_name() {
    if constexpr (std::same_as<T, double>) return "double";
    if constexpr (std::same_as<T, std::int32_t>) return "int32";
    if constexpr (std::same_as<T, std::uint32_t>) return "uint32";
    if constexpr (std::same_as<T, std::int64_t>) return "int64";
    if constexpr (std::same_as<T, std::uint64_t>) return "uint64";
    return "integer";
  }
  //! \p type names the value in messages, which are built only on failure.
  void read_bytes(unsigned char* bytes, std::size_t count, const std::string& what, const char* type);

  std::filesystem::path file_;
  std::ifstream in_;
  std::uint64_t size_ = 0;
  std::uint64_t offset_ = 0;
};

}  // namespace mvflow::io
