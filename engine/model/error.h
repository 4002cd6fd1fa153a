#pragma once
// The typed errors of mvflow. Library code never aborts or exits: it throws one of these, and
// the host (the CLI, an embedding program) decides what to do with it.

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace mvflow {

//! Base of every error mvflow throws on purpose.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

//! The content of an input (a file, a mesh, an option value) is not what was expected.
//! what() reads "FILE:LINE: message" (or "FILE: element N: message", or "FILE: message").
class InputError : public Error {
 public:
  //! \param line 1-based line number, or 0 when the position is not a line.
  InputError(std::filesystem::path file, std::size_t line, const std::string& message);
  //! An error about the element \p index (0-based) of kind \p element ("face", "camera", ...).
  InputError(std::filesystem::path file, const std::string& element, std::size_t index,
             const std::string& message);
  //! An error with no file (an option value, an in-memory mesh).
  explicit InputError(const std::string& message);

  const std::filesystem::path& file() const { return file_; }
  std::size_t line() const { return line_; }

 private:
  std::filesystem::path file_;
  std::size_t line_ = 0;
};

//! A file could not be opened, read, written or renamed.
class IoError : public Error {
 public:
  IoError(const std::filesystem::path& file, const std::string& message);
};

//! THROW_CHECK-style guard for API misuse: throws mvflow::Error naming the source location.
#define MVFLOW_CHECK(condition, message)                                                       \
  do {                                                                                         \
    if (!(condition))                                                                          \
      throw ::mvflow::Error(std::string(__FILE__) + ":" + std::to_string(__LINE__) + ": " + \
                            (message));                                                        \
  } while (false)

}  // namespace mvflow
