#pragma once
// Peak resident memory of this process, per measured configuration: Linux keeps the high-water
// mark in /proc/self/status (VmHWM) and resets it when "5" is written to /proc/self/clear_refs.

#include <cstddef>

namespace mvflow::perf {

//! Resets the high-water mark to the current resident size. False where Linux does not allow it
//! (then peak_memory_bytes() is the peak since the process started).
bool reset_peak_memory();
//! The high-water mark of the resident size (VmHWM) in bytes; 0 if unknown.
std::size_t peak_memory_bytes();
//! Returns freed heap memory to the system (malloc_trim), so a configuration's peak does not
//! include what an earlier step freed but the allocator kept.
void release_free_memory();

}  // namespace mvflow::perf
