// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// libFuzzer target: any bytes as a GLDF container (a ZIP archive), under small limits, then what
// `lumx info` and `lumx check` do next: the container listed, every photometry file inside read and
// summarised, and the full check (without an XSD). Only lumx::Error may come out of a reader, and
// check_gldf never throws.
//
//   bash scripts/fuzz.sh gldf 300
#include "fuzz_support.h"

#include <lumx/io/gldf_io.h>
#include <lumx/photometry/metrics.h>

#include <cstdlib>
#include <stdexcept>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static lumx_fuzz::ScratchFile container(".gldf");
  const std::string& path = container.write(data, size);
  lumx::GldfReadOptions o;
  o.limits.max_archive_bytes = 1u << 20;
  o.limits.max_entry_bytes = 4u << 20;
  o.limits.max_total_bytes = 16u << 20;
  o.photometry.warnings = [](const lumx::Diagnostic&) {};
  try {
    const lumx::GldfContainer c = lumx::read_gldf(path, o);
    for (const lumx::GldfFile& f : c.files) {
      if (f.content_type.rfind("ldc/", 0) != 0) continue;
      try {
        const lumx::Photometry p = lumx::read_gldf_photometry(c, f, o);
        (void)lumx::summarize(p);
      } catch (const lumx::Error&) {
      } catch (const std::invalid_argument&) {  // summarize() of a table it cannot integrate
      }
    }
    // Each call reopens and rechecks the archive: a few entries keep an input with thousands of them fast.
    for (std::size_t i = 0; i < c.entries.size() && i < 16; ++i) (void)lumx::read_gldf_entry(path, c.entries[i], o.limits);
  } catch (const lumx::Error&) {
  }
  try {
    (void)lumx::check_gldf(path, "", o);
  } catch (...) {
    std::abort();  // documented never to throw for bad input
  }
  return 0;
}
