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

/// Replaces `path` with `bytes`. Throws lumx::Error naming the path and the failing step.
void write_file_atomically(const std::string& path, std::string_view bytes);

/// Reads a whole file, refusing files larger than `max_bytes`. Throws lumx::Error.
std::string read_file_bounded(const std::string& path, std::size_t max_bytes);

LUMX_NAMESPACE_END
