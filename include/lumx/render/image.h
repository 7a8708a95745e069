// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/render/image.h — a float image with named channels: what lumx's renderers write and compare.
//
// Pixels are interleaved, row 0 at the top (as OpenEXR and PNG store them): pixels[(y · width + x) · C + c].
// Values carry the unit of the quantity rendered (lx for illuminance, cd/m² for luminance); the image does
// not know it, the writer of the file states it.
#pragma once

#include <lumx/version.h>

#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace render {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::string> channels;  ///< e.g. {"R", "G", "B"} or {"Y"}
  std::vector<float> pixels;

  Image() = default;
  Image(int w, int h, std::vector<std::string> channel_names, float value = 0.0f)
      : width(w), height(h), channels(std::move(channel_names)),
        pixels(std::size_t(w) * std::size_t(h) * channels.size(), value) {}

  std::size_t channel_count() const { return channels.size(); }
  std::size_t pixel_count() const { return std::size_t(width) * std::size_t(height); }
  float& at(int x, int y, int c = 0) { return pixels[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * channels.size() + std::size_t(c)]; }
  float at(int x, int y, int c = 0) const {
    return pixels[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * channels.size() + std::size_t(c)];
  }
  /// Index of the channel called `name`, or -1.
  int channel_index(std::string_view name) const {
    for (std::size_t c = 0; c < channels.size(); ++c)
      if (channels[c] == name) return int(c);
    return -1;
  }
};

}  // namespace render
LUMX_NAMESPACE_END
