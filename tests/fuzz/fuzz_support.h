#pragma once
// Shared by the libFuzzer targets (one per parser, *_fuzzer.cpp): the readers take file paths,
// so each input is written to a file of this process's own folder, and only mvflow's expected
// errors (InputError, IoError) count as a clean refusal. Anything else — another exception, a
// crash, a sanitizer report, a timeout or an allocation beyond libFuzzer's limits — is a finding.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <string_view>
#include <unistd.h>

#include "engine/model/error.h"

namespace mvflow::fuzz {

//! This process's folder for inputs, created on first use and removed at exit.
inline const std::filesystem::path& work_folder() {
  // Never destroyed: a static path object would be destroyed before the atexit handler (its
  // destructor is registered after the handler, when the initializer returns), which then
  // removed nothing and left a folder in /tmp behind every fuzz run.
  static const std::filesystem::path* const folder = [] {
    const auto* path =
        new std::filesystem::path(std::filesystem::temp_directory_path() / ("mvflow-fuzz-" + std::to_string(::getpid())));
    std::filesystem::create_directories(*path);
    std::atexit([] { std::error_code ignored; std::filesystem::remove_all(work_folder(), ignored); });
    return path;
  }();
  return *folder;
}

//! Writes \p size bytes to \p name in \p folder (default: the work folder) and returns its path.
inline std::filesystem::path write_input(const std::string& name, const std::uint8_t* data, std::size_t size,
                                         const std::filesystem::path& folder = work_folder()) {
  const auto file = folder / name;
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) std::abort();  // the fuzzer's own disk trouble, not a finding in the parser
  return file;
}

inline std::filesystem::path write_input(const std::string& name, std::string_view text,
                                         const std::filesystem::path& folder = work_folder()) {
  return write_input(name, reinterpret_cast<const std::uint8_t*>(text.data()), text.size(), folder);
}

//! Runs \p read; InputError and IoError are the reader refusing the input as it should. Any other
//! exception escapes and libFuzzer reports it (uncaught exception → abort) as a finding.
template <typename Read>
void expect_clean_refusal(Read&& read) {
  try {
    read();
  } catch (const InputError&) {
  } catch (const IoError&) {
  }
}

//! A model of two files (COLMAP's cameras and images): the input's first byte picks the file the
//! rest becomes (even: \p first_name, odd: \p second_name); the other is the valid file that
//! \p write_model puts in the same folder (once per folder). Then \p read_model reads the folder.
inline void fuzz_two_file_model(const std::uint8_t* data, std::size_t size, const char* first_name,
                                const char* second_name,
                                const std::function<void(const std::filesystem::path&)>& write_model,
                                const std::function<void(const std::filesystem::path&)>& read_model) {
  if (size == 0) return;
  const bool second = data[0] % 2 == 1;
  static const std::filesystem::path folders[2] = {work_folder() / "first", work_folder() / "second"};
  static bool written[2] = {false, false};
  const std::filesystem::path& folder = folders[second];
  if (!written[second]) {
    write_model(folder);
    written[second] = true;
  }
  write_input(second ? second_name : first_name, data + 1, size - 1, folder);
  expect_clean_refusal([&] { read_model(folder); });
}

}  // namespace mvflow::fuzz
