// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// src/io/bundle/exr_image.h — OpenEXR images encoded to and decoded from memory.
//
// Bundles checksum every payload before parsing it, so the bytes are in memory anyway; OpenEXR reads and
// writes them through in-memory streams (Imf::IStream / Imf::OStream) rather than file names.
#pragma once

#include <lumx/version.h>

#include <cstdint>
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

/// An OpenEXR image in memory, opened and checked but not yet decoded: the file must be exactly
/// `width` × `height` with exactly `channels` (any order in the file), data window at (0, 0), no
/// subsampling. Rows are then decoded straight into the caller's storage, so a payload is never held
/// twice. The bytes must outlive the reader. Every failure throws lumx::Error naming `file`.
class ExrReader {
 public:
  ExrReader(std::string_view bytes, const std::string& file, int width, int height,
            const std::vector<std::string>& channels);
  ~ExrReader();
  ExrReader(const ExrReader&) = delete;
  ExrReader& operator=(const ExrReader&) = delete;

  /// True when every channel is stored as half.
  bool half() const { return half_; }
  /// Decodes rows [y0, y1] into `out`: (y1 − y0 + 1) · width · channels floats, interleaved in the
  /// order of `channels`.
  void read_rows(int y0, int y1, float* out);

 private:
  struct Impl;
  Impl* impl_;
  std::string file_;
  int width_, height_;
  std::vector<std::string> channels_;
  bool half_ = true;
};

/// Size and channel names of an OpenEXR image in memory, from its header alone (nothing is decoded, so the
/// caller can check them against its limits before allocating). Channels are in the file's (alphabetical)
/// order. Throws lumx::Error naming `file`, also for a data window of no pixels or more than `max_pixels`
/// (checked before OpenEXR opens the image, which sizes its line buffers by it).
struct ExrLayout {
  int width = 0;
  int height = 0;
  std::vector<std::string> channels;
};
ExrLayout probe_exr(std::string_view bytes, const std::string& file, std::uint64_t max_pixels);

/// Decodes a whole image (for small payloads such as the radiance volume).
ExrImage decode_exr(std::string_view bytes, const std::string& file, int width, int height,
                    const std::vector<std::string>& channels);

}  // namespace detail
LUMX_NAMESPACE_END
