// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// System-call fault injection for the write tests (hard-cases.md §6 items 36–37). The test program defines
// write, pwrite, fsync and close itself; the dynamic linker binds every call to them, the library's and the
// C++ runtime's included (but not the C library's calls to itself, e.g. from fwrite or fclose), to these
// definitions, which forward to the next definition (dlsym(RTLD_NEXT)) unless a fault is armed.
// Only regular files opened for writing are counted and failed, so the test's own output is untouched.
#pragma once

#include <cstddef>
#include <cstdint>

namespace lumx_faults {

enum class Call {
  none,
  write,            ///< write/pwrite fail once `at_byte` bytes were written in all (a short write first)
  fsync_file,       ///< fsync of a regular file fails
  fsync_directory,  ///< fsync of a folder fails
  close_file,       ///< close of a regular file open for writing: the descriptor is released, then fails
};

struct Fault {
  Call call = Call::none;
  int error = 0;                 ///< errno to report, e.g. ENOSPC or EIO
  std::uint64_t at_byte = 0;     ///< Call::write: bytes that succeed before the first failure
  std::size_t max_chunk = 0;     ///< > 0: every write moves at most this many bytes (short writes), no failure
  int nth = 0;                   ///< fsync_file, fsync_directory, close_file: fail only the nth call (0: all)
};

/// Arms `fault` and clears the counters; disarm() restores the C library's behaviour.
void arm(const Fault& fault);
void disarm();
/// Bytes written to regular files since arm() (what succeeded, short writes included), by write and pwrite.
std::uint64_t bytes_written();
/// Of those, the bytes written by pwrite (positioned writes, e.g. a header completed at the end).
std::uint64_t bytes_pwritten();
/// Calls since arm() of fsync on a folder (to aim Fault::nth).
int directory_syncs();
/// How many calls failed because of the armed fault.
int failures_injected();

/// Arms a fault for the lifetime of the object.
struct Armed {
  explicit Armed(const Fault& f) { arm(f); }
  ~Armed() { disarm(); }
  Armed(const Armed&) = delete;
  Armed& operator=(const Armed&) = delete;
};

}  // namespace lumx_faults
