// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// src/io/bundle/sha256.h — SHA-256 digests of payload bytes (OpenSSL's libcrypto; FIPS 180-4).
#pragma once

#include <lumx/version.h>

#include <string>
#include <string_view>

LUMX_NAMESPACE_BEGIN
namespace detail {

/// Lowercase hexadecimal SHA-256 of `bytes` (64 characters).
std::string sha256_hex(std::string_view bytes);

}  // namespace detail
LUMX_NAMESPACE_END
