// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/render/image_io.h — lumx's rendered images as OpenEXR files (linear float, ZIP-compressed scanlines).
//
// Written atomically (lumx/io/atomic_file.h). Reading checks the header against ImageReadLimits before any
// pixel is allocated, and returns R, G, B, A first in that order when present, then the other channels in
// the file's order — so an RGB image reads back with the channels it was written with.
#pragma once

#include <lumx/render/image.h>

#include <cstdint>
#include <string>

LUMX_NAMESPACE_BEGIN

struct ImageReadLimits {
  std::uint64_t max_file_bytes = std::uint64_t(1) << 30;  ///< 1 GiB
  std::uint64_t max_values = std::uint64_t(1) << 28;      ///< width × height × channels (1 GiB of float)
};

/// Writes `image` (float, or half when `half`: values beyond ±65504 then become ±Inf, so callers choose
/// float for unbounded quantities). Throws lumx::Error naming `path`.
void write_exr_image(const std::string& path, const render::Image& image, bool half = false);

/// Reads a whole OpenEXR image. Throws lumx::Error naming `path` and the failing field or limit.
render::Image read_exr_image(const std::string& path, const ImageReadLimits& limits = {});

LUMX_NAMESPACE_END
