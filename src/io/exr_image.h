// src/io/exr_image.h — OpenEXR images encoded to and decoded from memory.
//
// Bundles checksum every payload before parsing it, so the bytes are in memory anyway; OpenEXR reads and
// writes them through in-memory streams (Imf::IStream / Imf::OStream) rather than file names.
#pragma once

#include <lumx/version.h>

#include <string>
#include <string_view>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace detail {

/// A float image with interleaved channels: pixels[(y · width + x) · channels.size() + c].
struct ExrImage {
  int width = 0;
  int height = 0;
  std::vector<std::string> channels;
  bool half = true;  ///< stored pixel type (HALF or FLOAT); values are float in memory either way
  std::vector<float> pixels;
};

/// Scanline OpenEXR, ZIP-compressed, with the given pixel type. Throws std::runtime_error on failure.
std::string encode_exr(const ExrImage& image);

/// Decodes `bytes` after checking that the file is exactly `width` × `height` with exactly `channels`
/// (any order in the file); nothing is allocated before those checks. Throws lumx::Error naming `file`.
ExrImage decode_exr(std::string_view bytes, const std::string& file, int width, int height,
                    const std::vector<std::string>& channels);


}  // namespace detail
LUMX_NAMESPACE_END
