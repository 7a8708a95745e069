// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// libFuzzer target: any bytes as a bundle's manifest.json (in a scratch bundle folder that also holds the
// seed bundle's payload, levels/level00_n00001_r0008.exr, so that a manifest naming it with its digest gets
// past the reader's checks to the payload), then what a renderer and `lumx check` do next: the reader's
// checks, every level and the volume loaded, the full check; and the same bytes as an OpenEXR payload of a
// few shapes, decoded with the bundle's own reader. Only lumx::Error may come out.
//
//   bash scripts/fuzz.sh bundle 300
#include <lumx/io/bundle_io.h>
#include <lumx/volume/radiance_volume.h>

#include "io/bundle/exr_image.h"

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <tuple>
#include <vector>

#include <unistd.h>

namespace {

const std::string& scratch_bundle() {
  static const std::string dir = [] {
    const std::string d = "/tmp/lumx_fuzz_bundle_" + std::to_string(::getpid());
    std::filesystem::create_directories(d + "/levels");
    std::error_code ec;  // without the seed payload, manifests stop at the missing file (still a valid run)
    std::filesystem::copy_file(LUMX_FUZZ_BUNDLE_PAYLOAD, d + "/levels/level00_n00001_r0008.exr",
                               std::filesystem::copy_options::overwrite_existing, ec);
    return d;
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string& dir = scratch_bundle();
  {
    std::FILE* f = std::fopen((dir + "/manifest.json").c_str(), "wb");
    if (!f) std::abort();
    if (size && std::fwrite(data, 1, size, f) != size) std::abort();
    std::fclose(f);
  }
  try {
    const lumx::BundleReader reader(dir);
    for (std::size_t k = 0; k < reader.manifest().levels.size(); ++k) (void)reader.load_level(k, 8);
    if (reader.has_volume()) (void)reader.load_volume();
  } catch (const lumx::Error&) {
  }
  (void)lumx::check_bundle(dir);  // never throws for bad content

  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  for (const auto& [w, h, channels] :
       {std::tuple<int, int, std::vector<std::string>>{16, 8, {"Y"}}, {32, 16, {"R", "G", "B"}}, {1, 1, {"Y"}}}) {
    try {
      (void)lumx::detail::decode_exr(bytes, "fuzz.exr", w, h, channels);
    } catch (const lumx::Error&) {
    }
  }
  return 0;
}
