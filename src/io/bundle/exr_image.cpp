// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// src/io/bundle/exr_image.cpp — OpenEXR through in-memory streams.
#include "io/bundle/exr_image.h"

#include <lumx/core/diagnostic.h>

#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <Iex.h>
#include <half.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <stdexcept>

LUMX_NAMESPACE_BEGIN
namespace detail {
namespace {

class StringOStream : public Imf::OStream {
 public:
  StringOStream() : Imf::OStream("<memory>") {}
  void write(const char c[], int n) override {
    const std::size_t end = position_ + std::size_t(n);
    if (end > bytes_.size()) bytes_.resize(end);
    std::memcpy(&bytes_[position_], c, std::size_t(n));
    position_ = end;
  }
  uint64_t tellp() override { return position_; }
  void seekp(uint64_t pos) override { position_ = std::size_t(pos); }
  std::string take() { return std::move(bytes_); }

 private:
  std::string bytes_;
  std::size_t position_ = 0;
};

class MemoryIStream : public Imf::IStream {
 public:
  MemoryIStream(std::string_view bytes, const std::string& name) : Imf::IStream(name.c_str()), bytes_(bytes) {}
  bool read(char c[], int n) override {
    if (n < 0 || position_ + std::size_t(n) > bytes_.size())
      throw Iex::InputExc("unexpected end of file");
    std::memcpy(c, bytes_.data() + position_, std::size_t(n));
    position_ += std::size_t(n);
    return position_ < bytes_.size();
  }
  uint64_t tellg() override { return position_; }
  void seekg(uint64_t pos) override { position_ = std::size_t(std::min<uint64_t>(pos, bytes_.size())); }

 private:
  std::string_view bytes_;
  std::size_t position_ = 0;
};

[[noreturn]] void fail(const std::string& file, const std::string& field, const std::string& message) {
  throw_at_field(file, field, message);
}

/// Walks the header's attributes before OpenEXR parses them, so that OpenEXR can only read what the header
/// describes consistently. OpenEXR allocates (and clears) an attribute's declared size before it reads the
/// value (a 29-byte payload declaring a 2 GiB attribute would cost 2 GiB), and it reads typed attributes by
/// their content: a fixed-size type declared with another size, or a channel list that does not end where
/// its size says, leaves OpenEXR reading the next attribute at another offset than the header's, where any
/// bytes become a size (found by fuzz_bundle: 1.9 GB for a 465-byte payload). So: every size must fit in
/// the bytes that follow; fixed-size types must have their size; a channel list, a string vector, a float
/// vector and a preview image must fill their declared size exactly; ID manifests (compressed) are refused. Single-part
/// scanline images only. Unknown types are read by OpenEXR as opaque bytes of the declared size.
/// The header's dataWindow as read by the walk (x0, y0, x1, y1; `found` false when the header has none).
struct HeaderWindow {
  bool found = false;
  std::int64_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  std::int64_t width() const { return x1 - x0 + 1; }
  std::int64_t height() const { return y1 - y0 + 1; }
};

/// Returns the dataWindow, so that callers check the image's size before OpenEXR opens it: OpenEXR sizes its
/// line buffers by the window as soon as it opens a file (a 223-byte payload declaring 33 554 448 pixels per
/// line made it allocate 1 GiB for its ZIP buffer, found by fuzz_bundle).
HeaderWindow check_exr_header(std::string_view b, const std::string& file) {
  HeaderWindow window;
  const auto u32 = [&](std::size_t at) {
    return std::uint32_t(std::uint8_t(b[at])) | std::uint32_t(std::uint8_t(b[at + 1])) << 8 |
           std::uint32_t(std::uint8_t(b[at + 2])) << 16 | std::uint32_t(std::uint8_t(b[at + 3])) << 24;
  };
  if (b.size() < 8 || u32(0) != 20000630u) throw_at_offset(file, 0, "OpenEXR", "not an OpenEXR image (magic number)");
  const std::uint32_t flags = u32(4) & ~0xffu;
  if (flags & ~0x400u)  // anything but long attribute names: tiled, deep or multi-part
    throw_at_offset(file, 4, "OpenEXR", "not a single-part scanline image (version flags " + std::to_string(flags) + ")");
  std::size_t at = 8;
  const auto zero_terminated = [&](std::size_t& pos, std::size_t end, const char* what) {
    const std::size_t stop = b.substr(0, end).find('\0', pos);
    if (stop == std::string_view::npos || stop - pos > 255)
      throw_at_offset(file, std::int64_t(pos), "OpenEXR header", std::string(what) + " is not terminated");
    const std::string_view s = b.substr(pos, stop - pos);
    pos = stop + 1;
    return s;
  };
  // OpenEXR 3.1's fixed-size attribute types (ImfStandardAttributes and the typed attributes it registers).
  static const std::pair<std::string_view, std::uint32_t> kFixed[] = {
      {"box2i", 16},    {"box2f", 16},  {"compression", 1}, {"chromaticities", 32}, {"double", 8}, {"envmap", 1},
      {"float", 4},     {"int", 4},     {"keycode", 28},    {"lineOrder", 1},       {"m33f", 36},  {"m33d", 72},
      {"m44f", 64},     {"m44d", 128},  {"rational", 8},    {"tiledesc", 9},        {"timecode", 8}, {"v2i", 8},
      {"v2f", 8},       {"v2d", 16},    {"v3i", 12},        {"v3f", 12},            {"v3d", 24},   {"deepImageState", 1}};
  for (int n = 0;; ++n) {
    if (n > 1024) throw_at_offset(file, std::int64_t(at), "OpenEXR header", "more than 1024 attributes");
    const std::string_view name = zero_terminated(at, b.size(), "attribute name");
    if (name.empty()) return window;
    const std::string_view type = zero_terminated(at, b.size(), "attribute type");
    if (b.size() - at < 4) throw_at_offset(file, std::int64_t(at), "OpenEXR header", "ends inside an attribute");
    const std::uint32_t size = u32(at);
    const std::string what = "attribute \"" + std::string(name) + "\" (" + std::string(type) + ")";
    if (size > b.size() - at - 4)
      throw_at_offset(file, std::int64_t(at), "OpenEXR header",
                      what + " declares " + std::to_string(size) + " bytes, " + std::to_string(b.size() - at - 4) + " follow");
    const std::size_t value = at + 4, end = value + size;
    auto inconsistent = [&](const std::string& why) {
      throw_at_offset(file, std::int64_t(at), "OpenEXR header", what + " declares " + std::to_string(size) + " bytes, " + why);
    };
    for (const auto& [fixed, bytes] : kFixed)
      if (type == fixed && size != bytes) inconsistent("its type has " + std::to_string(bytes));
    if (type == "chlist") {  // channels: name, then type, pLinear, 3 reserved bytes, xSampling, ySampling
      std::size_t pos = value;
      for (;;) {
        if (pos >= end) inconsistent("its channel list does not end within them");
        if (b[pos] == '\0') {
          ++pos;
          break;
        }
        (void)zero_terminated(pos, end, "channel name");
        if (end - pos < 16) inconsistent("a channel's description runs past them");
        pos += 16;
      }
      if (pos != end) inconsistent("its channel list ends after " + std::to_string(pos - value));
    } else if (type == "stringvector") {  // strings, each a 4-byte length and its bytes
      std::size_t pos = value;
      while (pos < end) {
        if (end - pos < 4 || u32(pos) > end - pos - 4) inconsistent("its strings do not fill them");
        pos += 4 + u32(pos);
      }
    } else if (type == "preview") {  // width, height, then width · height RGBA bytes
      if (size < 8 || std::uint64_t(u32(value)) * u32(value + 4) * 4 != std::uint64_t(size) - 8)
        inconsistent("not 8 plus 4 bytes per preview pixel");
    } else if (type == "floatvector") {  // OpenEXR reads size / 4 floats: a remainder would be left unread
      if (size % 4 != 0) inconsistent("not a whole number of 4-byte floats");
    } else if (type == "idmanifest") {
      throw_at_offset(file, std::int64_t(at), "OpenEXR header", what + ": compressed ID manifests are not read");
    } else if (name == "dataWindow" && type == "box2i") {  // 16 bytes (checked above): four int32
      const auto i32 = [&](std::size_t pos) { return std::int64_t(std::int32_t(u32(pos))); };
      window = {true, i32(value), i32(value + 4), i32(value + 8), i32(value + 12)};
    }
    at = end;
  }
}

}  // namespace

std::string encode_exr(const ExrImage& image) {
  const std::size_t nc = image.channels.size();
  if (image.pixels.size() != std::size_t(image.width) * std::size_t(image.height) * nc)
    throw std::logic_error("encode_exr: pixel count does not match the image size");
  Imf::Header header(image.width, image.height);
  header.compression() = Imf::ZIP_COMPRESSION;
  const Imf::PixelType type = image.half ? Imf::HALF : Imf::FLOAT;
  // OpenEXR writes a channel from a slice of the same type: round to half here (round-to-nearest-even,
  // Imath::half; callers have checked the range, so nothing becomes Inf).
  std::vector<Imath::half> halves;
  if (image.half) halves.assign(image.pixels.begin(), image.pixels.end());
  const std::size_t bytes = image.half ? sizeof(Imath::half) : sizeof(float);
  char* base = image.half ? (char*)halves.data() : (char*)image.pixels.data();
  Imf::FrameBuffer frame;
  for (std::size_t c = 0; c < nc; ++c) {
    header.channels().insert(image.channels[c], Imf::Channel(type));
    frame.insert(image.channels[c], Imf::Slice(type, base + c * bytes, bytes * nc, bytes * nc * std::size_t(image.width)));
  }
  StringOStream out;
  {
    Imf::OutputFile file(out, header);
    file.setFrameBuffer(frame);
    file.writePixels(image.height);
  }
  return out.take();
}

struct ExrReader::Impl {
  MemoryIStream stream;
  Imf::InputFile file;
  Impl(std::string_view bytes, const std::string& name) : stream(bytes, name), file(stream) {}
};

ExrReader::ExrReader(std::string_view bytes, const std::string& file, int width, int height,
                     const std::vector<std::string>& channels)
    : impl_(nullptr), file_(file), width_(width), height_(height), channels_(channels) {
  const HeaderWindow declared = check_exr_header(bytes, file);
  if (!declared.found) fail(file, "dataWindow", "missing");
  if (declared.found && (declared.x0 != 0 || declared.y0 != 0))
    fail(file, "dataWindow", "does not start at (0, 0)");
  if (declared.found && (declared.width() != width || declared.height() != height))
    fail(file, "dataWindow", "image is " + std::to_string(declared.width()) + " × " + std::to_string(declared.height()) +
                                 ", the manifest says " + std::to_string(width) + " × " + std::to_string(height));
  try {
    impl_ = new Impl(bytes, file);
    const Imf::Header& header = impl_->file.header();  // its dataWindow is `declared` (OpenEXR requires one)
    std::size_t found = 0;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
      if (std::find(channels.begin(), channels.end(), std::string(it.name())) == channels.end())
        fail(file, "channels", std::string("unexpected channel \"") + it.name() + "\"");
      if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
        fail(file, "channels", std::string("channel \"") + it.name() + "\" is subsampled");
      half_ = half_ && it.channel().type == Imf::HALF;
      ++found;
    }
    if (found != channels.size())
      fail(file, "channels", "has " + std::to_string(found) + " channels, expected " + std::to_string(channels.size()));
  } catch (const Error&) {
    delete impl_;
    throw;
  } catch (const std::exception& e) {
    delete impl_;
    fail(file, "OpenEXR", e.what());
  }
}

ExrReader::~ExrReader() { delete impl_; }

void ExrReader::read_rows(int y0, int y1, float* out) {
  if (y0 < 0 || y1 < y0 || y1 >= height_) throw std::logic_error("ExrReader::read_rows: rows out of range");
  try {
    const std::size_t nc = channels_.size();
    // OpenEXR addresses a slice by absolute (x, y); Slice::Make places `out` at the origin (0, y0).
    const std::size_t row = nc * std::size_t(width_);
    Imf::FrameBuffer frame;
    for (std::size_t c = 0; c < nc; ++c)
      frame.insert(channels_[c], Imf::Slice::Make(Imf::FLOAT, out + c, Imath::V2i(0, y0), width_, y1 - y0 + 1,
                                                  sizeof(float) * nc, sizeof(float) * row));
    impl_->file.setFrameBuffer(frame);
    impl_->file.readPixels(y0, y1);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    fail(file_, "OpenEXR", e.what());
  }
}

ExrLayout probe_exr(std::string_view bytes, const std::string& file, std::uint64_t max_pixels) {
  const HeaderWindow declared = check_exr_header(bytes, file);
  if (declared.found && (declared.width() <= 0 || declared.height() <= 0 ||
                         std::uint64_t(declared.width()) * std::uint64_t(declared.height()) > max_pixels))
    fail(file, "dataWindow", std::to_string(declared.width()) + " × " + std::to_string(declared.height()) +
                                 " pixels: none, or more than ImageReadLimits::max_values (" +
                                 std::to_string(max_pixels) + ")");
  try {
    MemoryIStream stream(bytes, file);
    Imf::InputFile input(stream);
    const Imath::Box2i window = input.header().dataWindow();
    if (window.min.x != 0 || window.min.y != 0) fail(file, "dataWindow", "does not start at (0, 0)");
    ExrLayout layout;
    layout.width = window.max.x + 1;
    layout.height = window.max.y + 1;
    for (auto it = input.header().channels().begin(); it != input.header().channels().end(); ++it)
      layout.channels.emplace_back(it.name());
    return layout;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    fail(file, "OpenEXR", e.what());
  }
}

ExrImage decode_exr(std::string_view bytes, const std::string& file, int width, int height,
                    const std::vector<std::string>& channels) {
  ExrReader reader(bytes, file, width, height, channels);
  ExrImage image;
  image.width = width;
  image.height = height;
  image.channels = channels;
  image.half = reader.half();
  image.pixels.assign(std::size_t(width) * std::size_t(height) * channels.size(), 0.0f);
  reader.read_rows(0, height - 1, image.pixels.data());
  return image;
}

}  // namespace detail
LUMX_NAMESPACE_END
