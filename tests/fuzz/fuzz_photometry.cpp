// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// libFuzzer target: any bytes through the IES, EULUMDAT and TM-33 (XML and JSON) readers, validation, the
// intensity table and the writers.
// Only lumx::Error may come out of a reader; a table that was read must survive everything after it.
//
//   bash scripts/fuzz.sh photometry 300
#include <lumx/photometry/intensity_table.h>
#include <lumx/io/photometry_io.h>
#include <lumx/io/tm33_io.h>
#include <lumx/photometry/metrics.h>
#include <lumx/photometry/validate.h>

#include <cstdint>
#include <cstdlib>
#include <string_view>

namespace {

void exercise(const lumx::Photometry& p) {
  (void)lumx::validate(p);
  try {
    const lumx::PhotometricSummary s = lumx::summarize(p);
    if (!(s.flux_lm >= 0) && p.candela.size() > 0) {
      bool negative = false;
      for (double c : p.candela) negative = negative || c < 0;
      if (!negative) std::abort();  // non-negative table, NaN or negative flux: a bug
    }
  } catch (const std::invalid_argument&) {
  }
  try {
    (void)lumx::read_ies(lumx::format_ies(p), "rt.ies");
    if (p.type == lumx::PhotometricType::C) (void)lumx::read_ldt(lumx::format_ldt(p), "rt.ldt");
    (void)lumx::read_tm33_xml(lumx::format_tm33_xml(p), "rt.xml");
    (void)lumx::read_tm33_json(lumx::format_tm33_json(p), "rt.json");
  } catch (const lumx::Error&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  lumx::ReadOptions o;
  o.warnings = [](const lumx::Diagnostic&) {};
  for (int format = 0; format < 4; ++format) {
    try {
      const lumx::Photometry p = format == 0   ? lumx::read_ies(text, "fuzz.ies", o)
                                 : format == 1 ? lumx::read_ldt(text, "fuzz.ldt", o)
                                 : format == 2 ? lumx::read_tm33_xml(text, "fuzz.xml", o)
                                               : lumx::read_tm33_json(text, "fuzz.json", o);
      exercise(p);
    } catch (const lumx::Error&) {
    }
  }
  return 0;
}
