// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// src/io/bundle/sha256.cpp — SHA-256 through OpenSSL's EVP interface (no hand-rolled crypto).
#include "io/bundle/sha256.h"

#include <openssl/evp.h>

#include <stdexcept>

LUMX_NAMESPACE_BEGIN
namespace detail {

std::string sha256_hex(std::string_view bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), digest, &length, EVP_sha256(), nullptr) != 1 || length != 32)
    throw std::runtime_error("SHA-256: OpenSSL EVP_Digest failed");
  static const char* hex = "0123456789abcdef";
  std::string out(64, '0');
  for (unsigned i = 0; i < 32; ++i) {
    out[2 * i] = hex[digest[i] >> 4];
    out[2 * i + 1] = hex[digest[i] & 15];
  }
  return out;
}

}  // namespace detail
LUMX_NAMESPACE_END
