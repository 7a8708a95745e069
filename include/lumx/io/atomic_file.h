// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/io/atomic_file.h — replace a file's contents all at once or not at all.
//
// Write to a temporary file in the target's folder, fsync it, close it (checking the result), rename it
// over the target, then fsync the folder (hard-cases.md §4). On any failure the temporary file is
// removed and the previous target is untouched.
#pragma once

#include <lumx/version.h>

#include <string>
#include <string_view>

LUMX_NAMESPACE_BEGIN

/// A fresh name for a temporary sibling of `target`: ".NAME.tmp-PID-N" in its folder (hidden, and on the
/// same file system, so a rename to `target` is atomic). The process id lets remove_stale_temporaries tell
/// a temporary of a killed writer from one still being written.
std::string temporary_sibling_name(const std::string& target);

/// Removes the temporaries of `target` (files or folders named as temporary_sibling_name makes them) left by
/// processes that no longer run — a writer killed with SIGKILL cannot clean up after itself; the next
/// write of the same target does. Best effort: what cannot be removed is left.
void remove_stale_temporaries(const std::string& target);

/// Replaces `path` with `bytes`. Throws lumx::Error naming the path and the failing step.
void write_file_atomically(const std::string& path, std::string_view bytes);

/// Makes `folder`'s entries (a rename into it) durable. A file system that cannot sync folders (EINVAL) is
/// not an error; any other failure throws lumx::Error located at `reported_path`, the path the caller was
/// asked to write. `replaced`: the new version is already in place, and the message says so.
void sync_folder(const std::string& folder, const std::string& reported_path, bool replaced);

/// Reads a whole file, refusing files larger than `max_bytes`; the error names `limit_name` (the option that
/// set the bound, e.g. "ReadLimits::max_file_bytes") when given. Throws lumx::Error.
std::string read_file_bounded(const std::string& path, std::size_t max_bytes, const std::string& limit_name = {});

LUMX_NAMESPACE_END
