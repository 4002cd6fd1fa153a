#pragma once
// Line-by-line reading of text formats with errors that name the file and the line.

#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace mvflow::io {

class TextReader {
 public:
  //! \throw IoError when the file cannot be opened.
  explicit TextReader(std::filesystem::path file);

  //! Reads the next line into line(); skips nothing. Returns false at the end of the file.
  bool next_line();
  //! Reads the next line that is neither empty nor only whitespace nor a comment starting with
  //! \p comment (when non-zero). Returns false at the end of the file.
  bool next_content_line(char comment = '#');
  //! Like next_content_line, but the end of the file is an error: "expected WHAT".
  void require_content_line(const std::string& what, char comment = '#');

  const std::string& line() const { return line_; }
  std::size_t line_number() const { return line_number_; }
  const std::filesystem::path& file() const { return file_; }
  std::istream& stream() { return in_; }

  //! Throws InputError "FILE:LINE: message" at the current line.
  [[noreturn]] void fail(const std::string& message) const;

 private:
  std::filesystem::path file_;
  std::ifstream in_;
  std::string line_;
  std::size_t line_number_ = 0;
};

//! Splits on whitespace.
std::vector<std::string_view> split_whitespace(std::string_view text);

//! Parses a finite double; otherwise throws InputError at \p reader's line naming \p what and the
//! token ("expected a number for 'k11', got 'abc'"; "... got 'nan' (not finite)").
double parse_double(const TextReader& reader, std::string_view token, const std::string& what);
//! Parses a non-negative integer that fits in long long, the same way.
long long parse_integer(const TextReader& reader, std::string_view token, const std::string& what);

//! How many of \p count elements to reserve room for when each takes at least \p min_bytes bytes
//! of \p file: never more than the file can hold, so that a count in a header ("element vertex
//! 215155252") allocates nothing beyond what the file really contains.
std::size_t reservable(std::size_t count, const std::filesystem::path& file, std::size_t min_bytes);

}  // namespace mvflow::io
