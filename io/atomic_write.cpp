#include "io/atomic_write.h"

#include <unistd.h>

#include <atomic>
#include <fstream>
#include <system_error>

#include "engine/model/error.h"

namespace mvflow::io {

namespace {

std::filesystem::path temporary_beside(const std::filesystem::path& destination) {
  static std::atomic<unsigned> counter{0};
  const auto folder = destination.has_parent_path() ? destination.parent_path() : std::filesystem::path(".");
  // ".name.tmp-PID-N.ext": hidden, unique per process and call, same extension.
  return folder / ("." + destination.stem().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                   std::to_string(counter++) + destination.extension().string());
}

void commit(const std::filesystem::path& temporary, const std::filesystem::path& destination) {
  std::error_code error;
  std::filesystem::rename(temporary, destination, error);
  if (error) {
    std::filesystem::remove(temporary, error);
    throw IoError(destination, "cannot rename the finished temporary file into place");
  }
}

}  // namespace

void check_writable(const std::filesystem::path& destination) {
  std::error_code error;
  const auto folder = destination.has_parent_path() ? destination.parent_path() : std::filesystem::path(".");
  if (!std::filesystem::is_directory(folder, error))
    throw IoError(destination, "cannot be written: the folder " + folder.string() + " does not exist");
  if (std::filesystem::is_directory(destination, error))
    throw IoError(destination, "cannot be written: it is a folder");
  const auto probe = temporary_beside(destination);
  {
    std::ofstream out(probe, std::ios::binary | std::ios::trunc);
    if (!out) throw IoError(destination, "cannot be written: its folder does not take new files");
  }
  std::filesystem::remove(probe, error);
}

void prepare_output_folder(const std::filesystem::path& folder) {
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error) throw IoError(folder, "cannot be created as the output folder: " + error.message());
  check_writable(folder / "probe");
}

void write_atomically_to_path(const std::filesystem::path& destination,
                              const std::function<void(const std::filesystem::path&)>& write) {
  const auto temporary = temporary_beside(destination);
  try {
    write(temporary);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw;
  }
  if (!std::filesystem::exists(temporary)) throw IoError(destination, "the writer produced no file");
  commit(temporary, destination);
}

void write_atomically(const std::filesystem::path& destination, bool binary,
                      const std::function<void(std::ostream&)>& write) {
  write_atomically_to_path(destination, [&](const std::filesystem::path& temporary) {
    std::ofstream out(temporary, binary ? std::ios::binary | std::ios::trunc : std::ios::trunc);
    if (!out) throw IoError(destination, "cannot open a temporary file for writing in its folder");
    write(out);
    out.flush();
    if (!out) throw IoError(destination, "write failed (disk full?)");
  });
}

}  // namespace mvflow::io
