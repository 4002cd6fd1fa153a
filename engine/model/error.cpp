#include "engine/model/error.h"

namespace mvflow {

namespace {
std::string located(const std::filesystem::path& file, std::size_t line, const std::string& message) {
  // Appends instead of operator+ chains: GCC 12 warns falsely (-Wrestrict) on those.
  std::string where = file.string();
  if (line > 0) where.append(":").append(std::to_string(line));
  where.append(": ").append(message);
  return where;
}
}  // namespace

InputError::InputError(std::filesystem::path file, std::size_t line, const std::string& message)
    : Error(located(file, line, message)), file_(std::move(file)), line_(line) {}

InputError::InputError(std::filesystem::path file, const std::string& element, std::size_t index,
                       const std::string& message)
    : Error(located(file, 0, element + " " + std::to_string(index) + ": " + message)),
      file_(std::move(file)) {}

InputError::InputError(const std::string& message) : Error(message) {}

IoError::IoError(const std::filesystem::path& file, const std::string& message)
    : Error(located(file, 0, message)) {}

}  // namespace mvflow
