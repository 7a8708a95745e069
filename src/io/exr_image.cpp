// src/io/exr_image.cpp — OpenEXR through in-memory streams.
#include "io/exr_image.h"

#include <lumx/diagnostic.h>

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

ExrImage decode_exr(std::string_view bytes, const std::string& file, int width, int height,
                    const std::vector<std::string>& channels) {
  try {
    MemoryIStream in(bytes, file);
    Imf::InputFile exr(in);
    const Imath::Box2i window = exr.header().dataWindow();
    const long long w = (long long)window.max.x - window.min.x + 1;
    const long long h = (long long)window.max.y - window.min.y + 1;
    if (window.min.x != 0 || window.min.y != 0)
      fail(file, "dataWindow", "does not start at (0, 0)");
    if (w != width || h != height)
      fail(file, "dataWindow", "image is " + std::to_string(w) + " × " + std::to_string(h) + ", the manifest says " +
                                   std::to_string(width) + " × " + std::to_string(height));
    ExrImage image;
    image.width = width;
    image.height = height;
    image.channels = channels;
    std::size_t found = 0;
    bool all_half = true;
    for (auto it = exr.header().channels().begin(); it != exr.header().channels().end(); ++it) {
      if (std::find(channels.begin(), channels.end(), std::string(it.name())) == channels.end())
        fail(file, "channels", std::string("unexpected channel \"") + it.name() + "\"");
      if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
        fail(file, "channels", std::string("channel \"") + it.name() + "\" is subsampled");
      all_half = all_half && it.channel().type == Imf::HALF;
      ++found;
    }
    if (found != channels.size())
      fail(file, "channels", "has " + std::to_string(found) + " channels, expected " + std::to_string(channels.size()));
    image.half = all_half;
    const std::size_t nc = channels.size();
    image.pixels.assign(std::size_t(width) * std::size_t(height) * nc, 0.0f);
    Imf::FrameBuffer frame;
    for (std::size_t c = 0; c < nc; ++c)
      frame.insert(channels[c], Imf::Slice(Imf::FLOAT, (char*)(image.pixels.data() + c),
                                           sizeof(float) * nc, sizeof(float) * nc * std::size_t(width)));
    exr.setFrameBuffer(frame);
    exr.readPixels(0, height - 1);
    return image;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    fail(file, "OpenEXR", e.what());
  }
}


}  // namespace detail
LUMX_NAMESPACE_END
