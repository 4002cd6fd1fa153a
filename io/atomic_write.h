#pragma once
// Writers never leave a half-written output: they write a temporary file in the destination's
// folder and rename it over the destination only when everything succeeded.

#include <filesystem>
#include <functional>
#include <ostream>

namespace mvflow::io {

//! Calls \p write with a stream to a temporary file beside \p destination, then renames it.
//! On any exception (or a stream failure, reported as IoError) the temporary file is removed
//! and \p destination is untouched.
void write_atomically(const std::filesystem::path& destination, bool binary,
                      const std::function<void(std::ostream&)>& write);

//! The same for writers that need a file name (OpenCV, OpenMesh): \p write receives the
//! temporary path, which keeps the destination's extension so format detection still works.
void write_atomically_to_path(const std::filesystem::path& destination,
                              const std::function<void(const std::filesystem::path&)>& write);

//! Checks, before any long work, that write_atomically can later write \p destination: its
//! folder exists and takes a new file (a probe file is created and removed), and the destination
//! is not a folder. \throw IoError naming \p destination and what is wrong.
void check_writable(const std::filesystem::path& destination);

//! Creates \p folder (and its parents) if missing and checks that it takes new files, before any
//! long work that writes into it. \throw IoError naming \p folder and what is wrong.
void prepare_output_folder(const std::filesystem::path& folder);

}  // namespace mvflow::io
