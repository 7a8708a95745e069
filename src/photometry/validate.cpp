// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include <lumx/photometry/intensity_table.h>
#include <lumx/photometry/metrics.h>
#include <lumx/photometry/validate.h>

#include "photometry/number_text.h"

#include <cmath>
#include <cstdio>
#include <string>

LUMX_NAMESPACE_BEGIN
namespace {

std::string num(double v) { return detail::format_number(v, 6); }

}  // namespace

std::vector<Diagnostic> validate(const Photometry& p) {
  std::vector<Diagnostic> out;
  auto add = [&](Severity s, int line, const std::string& field, const std::string& msg) {
    out.push_back(Diagnostic{s, p.source.file, line, -1, field, msg});
  };
  auto line_of = [](const std::vector<std::uint32_t>& lines, std::size_t i) {
    return i < lines.size() ? static_cast<int>(lines[i]) : 0;
  };
  const std::size_t nh = p.horizontal_deg.size(), nv = p.vertical_deg.size();
  if (nv < 2 || nh < 1 || p.candela.size() != nh * nv) {
    add(Severity::error, 0, "candela",
        "table holds " + std::to_string(p.candela.size()) + " values for " + std::to_string(nh) + " x " +
            std::to_string(nv) + " angles");
    return out;
  }
  for (std::size_t i = 1; i < nv; ++i)
    if (!(p.vertical_deg[i] > p.vertical_deg[i - 1]))
      add(Severity::error, line_of(p.source.vertical_lines, i), "vertical angle", "angles must strictly increase");
  for (std::size_t i = 1; i < nh; ++i)
    if (!(p.horizontal_deg[i] > p.horizontal_deg[i - 1]))
      add(Severity::error, line_of(p.source.horizontal_lines, i), "horizontal angle", "angles must strictly increase");
  double peak = 0;
  bool finite = true;
  for (std::size_t i = 0; i < p.candela.size(); ++i) {
    const double c = p.candela[i];
    if (!std::isfinite(c)) {
      add(Severity::error, line_of(p.source.candela_lines, i), "candela", "value is not finite");
      finite = false;
    }
    if (c > peak) peak = c;
  }
  std::size_t negatives = 0;
  for (std::size_t i = 0; i < p.candela.size(); ++i)
    if (p.candela[i] < 0 && negatives++ == 0)
      add(Severity::warning, line_of(p.source.candela_lines, i), "candela",
          "negative intensity " + num(p.candela[i]) + " cd (first of the negative values)");
  bool any_error = false;
  for (const auto& d : out) any_error = any_error || d.severity == Severity::error;
  if (!finite || any_error) return out;
  if (!(peak > 0)) {
    add(Severity::error, line_of(p.source.candela_lines, 0), "candela", "every intensity is zero: no light");
    return out;
  }

  // One value per pole: every plane must agree where the planes meet (gamma 0 and 180 for Type C).
  if (p.type == PhotometricType::C && nh > 1) {
    for (std::size_t iv : {std::size_t{0}, nv - 1}) {
      const double g = p.vertical_deg[iv];
      if (std::abs(g) > 1e-9 && std::abs(g - 180) > 1e-9) continue;
      double lo = p.at(0, iv), hi = lo;
      for (std::size_t ih = 1; ih < nh; ++ih) {
        lo = std::min(lo, p.at(ih, iv));
        hi = std::max(hi, p.at(ih, iv));
      }
      if (hi - lo > 0.01 * peak)
        add(Severity::warning, line_of(p.source.candela_lines, iv), "candela",
            "planes disagree at gamma " + num(g) + " (" + num(lo) + " to " + num(hi) +
                " cd) although they meet in one direction; lumx uses their mean");
    }
  }

  // C0 and C360 are one plane; a file storing both should give them the same values.
  if (p.type == PhotometricType::C && nh > 1 && std::abs(p.horizontal_deg.front()) < 1e-9 &&
      std::abs(p.horizontal_deg.back() - 360.0) < 1e-9) {
    double worst = 0;
    for (std::size_t iv = 0; iv < nv; ++iv) worst = std::max(worst, std::abs(p.at(0, iv) - p.at(nh - 1, iv)));
    if (worst > 0.01 * peak)
      add(Severity::warning, line_of(p.source.candela_lines, (nh - 1) * nv), "candela",
          "planes C0 and C360 differ by up to " + num(worst) + " cd although they are one plane; lumx uses their mean");
  }

  PhotometricSummary s;
  try {
    s = summarize(p);
  } catch (const std::exception& e) {
    add(Severity::error, 0, "horizontal angle", e.what());
    return out;
  }
  if (!(s.flux_lm > 0)) add(Severity::error, 0, "candela", "total flux is not positive");

  if (s.light_output_ratio && *s.light_output_ratio > 1.0 + 1e-3)
    add(Severity::warning, 0, "lumens per lamp",
        "luminaire flux " + num(s.flux_lm) + " lm exceeds the rated lamp flux " + num(s.rated_lamp_flux_lm) +
            " lm (light output ratio " + num(*s.light_output_ratio) + ")");
  if (!(p.ballast_factor > 0) || p.ballast_factor > 2)
    add(Severity::warning, 0, "ballast factor", "implausible value " + num(p.ballast_factor));
  if (p.opening.shape() == LuminousShape::unknown)
    add(Severity::warning, 0, "luminous opening",
        "sign pattern of width/length/height (" + num(p.opening.width_m) + ", " + num(p.opening.length_m) + ", " +
            num(p.opening.height_m) + ") is not in LM-63-2019 Table 1");

  if (p.source.format == "IES") {
    const bool v2002 = p.source.version == file_format::kIes2002, v2019 = p.source.version == file_format::kIes2019;
    if (v2002 || v2019)
      for (const char* k : {"TEST", "TESTLAB", "ISSUEDATE", "MANUFAC"})
        if (!p.find_keyword(k))
          add(Severity::warning, 0, "keyword", std::string("required keyword [") + k + "] is missing (" +
                                                    p.source.version + ")");
    if (v2019) {
      const double g = p.ies_second_factor;
      const bool ok = is_lm63_2019_file_generation_type(g);
      if (!ok) add(Severity::warning, 0, "file generation type", num(g) + " is not a value of LM-63-2019 Table 2");
    }
  }
  if (p.source.format == "EULUMDAT") {
    const double dff = 100.0 * s.downward_fraction;
    if (std::abs(dff - p.ldt.dff_percent) > 1.0)
      add(Severity::warning, 22, "DFF", "stated downward flux fraction " + num(p.ldt.dff_percent) +
                                            " % differs from the table's " + num(dff) + " %");
    if (s.light_output_ratio && p.ldt.lor_percent > 0 &&
        std::abs(100.0 * *s.light_output_ratio - p.ldt.lor_percent) > 0.02 * p.ldt.lor_percent)
      add(Severity::warning, 23, "LORL", "stated light output ratio " + num(p.ldt.lor_percent) +
                                             " % differs from the table's " + num(100.0 * *s.light_output_ratio) + " %");
  }
  return out;
}

LUMX_NAMESPACE_END
