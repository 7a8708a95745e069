// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// libFuzzer target: any bytes as a ray file of each format (TM-25, LightTools binary and text, Zemax binary
// and text, plain text), then what a user does next: the rays summarised, streamed twice, written as TM-25
// and read back. Only lumx::Error may come out; rays that were read must be finite with unit directions.
//
//   bash scripts/fuzz.sh rayset 300
#include "fuzz_support.h"

#include <lumx/io/rayset_io.h>

#include <cmath>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static lumx_fuzz::ScratchFile input(".rays"), copy(".tm25ray");
  const std::string& path = input.write(data, size);
  lumx::RaysetReadOptions o;
  o.warnings = [](const lumx::Diagnostic&) {};
  o.limits.max_rays = 1u << 20;  // the file size bounds the count anyway; keep each run short
  for (const lumx::RaysetFormat f :
       {lumx::RaysetFormat::tm25, lumx::RaysetFormat::lighttools_binary, lumx::RaysetFormat::lighttools_text,
        lumx::RaysetFormat::zemax_binary, lumx::RaysetFormat::zemax_text, lumx::RaysetFormat::plain_text}) {
    o.format = f;
    try {
      auto rays = lumx::open_rayset(path, o);
      const lumx::RaysetSummary s = lumx::summarize_rays(*rays, 4096);
      rays->rewind();
      lumx::RayChunk c;
      while (rays->next(c, 4096))
        for (std::size_t i = 0; i < c.size(); ++i) {
          const float len = std::sqrt(c.dx[i] * c.dx[i] + c.dy[i] * c.dy[i] + c.dz[i] * c.dz[i]);
          if (!(std::abs(len - 1.0f) < 1e-3f) || !std::isfinite(c.x[i]) || !(c.flux[i] >= 0)) std::abort();
        }
      if (s.rays > 0 && s.rays < 10000) {  // what was read survives a TM-25 round trip, ray for ray
        lumx::write_tm25(copy.path(), rays->info(), *rays);
        lumx::RaysetReadOptions back_options = o;
        back_options.format = lumx::RaysetFormat::tm25;
        auto back = lumx::open_rayset(copy.path(), back_options);
        if (lumx::summarize_rays(*back).rays != s.rays) std::abort();
      }
    } catch (const lumx::Error&) {
    }
  }
  return 0;
}
