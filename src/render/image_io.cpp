// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// src/render/image_io.cpp — OpenEXR image files through the in-memory codec of the bundle payloads.
#include <lumx/render/image_io.h>

#include <lumx/core/diagnostic.h>
#include <lumx/io/atomic_file.h>

#include "io/bundle/exr_image.h"

#include <algorithm>
#include <stdexcept>

LUMX_NAMESPACE_BEGIN

void write_exr_image(const std::string& path, const render::Image& image, bool half) {
  if (image.width <= 0 || image.height <= 0 || image.channels.empty() ||
      image.pixels.size() != image.pixel_count() * image.channel_count())
    throw_at_field(path, "image", "has no pixels or its pixel count does not match width × height × channels");
  detail::ExrImage exr;
  exr.width = image.width;
  exr.height = image.height;
  exr.channels = image.channels;
  exr.half = half;
  exr.pixels = image.pixels;
  std::string bytes;
  try {
    bytes = detail::encode_exr(exr);
  } catch (const std::exception& e) {
    throw_at_field(path, "OpenEXR", e.what());
  }
  write_file_atomically(path, bytes);
}

render::Image read_exr_image(const std::string& path, const ImageReadLimits& limits) {
  const std::string bytes = read_file_bounded(path, std::size_t(limits.max_file_bytes));
  const detail::ExrLayout layout = detail::probe_exr(bytes, path, limits.max_values);
  const std::uint64_t values =
      std::uint64_t(layout.width) * std::uint64_t(layout.height) * std::uint64_t(layout.channels.size());
  if (layout.width <= 0 || layout.height <= 0 || layout.channels.empty())
    throw_at_field(path, "dataWindow", "image has no pixels or no channels");
  if (values > limits.max_values)
    throw_at_field(path, "dataWindow",
                   std::to_string(layout.width) + " × " + std::to_string(layout.height) + " × " +
                       std::to_string(layout.channels.size()) + " values exceed ImageReadLimits::max_values (" +
                       std::to_string(limits.max_values) + ")");
  // R, G, B, A first (OpenEXR stores channels alphabetically), then the rest in file order.
  std::vector<std::string> order;
  for (const char* name : {"R", "G", "B", "A"})
    if (std::find(layout.channels.begin(), layout.channels.end(), name) != layout.channels.end()) order.emplace_back(name);
  for (const std::string& c : layout.channels)
    if (std::find(order.begin(), order.end(), c) == order.end()) order.push_back(c);
  detail::ExrImage exr = detail::decode_exr(bytes, path, layout.width, layout.height, order);
  render::Image image;
  image.width = exr.width;
  image.height = exr.height;
  image.channels = std::move(exr.channels);
  image.pixels = std::move(exr.pixels);
  return image;
}

LUMX_NAMESPACE_END
