// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// EULUMDAT (.ldt) writer (formats.md §2).
//
// Writes the layout read by ldt_reader.cpp: one field per line, CR LF line ends (the original MS-DOS
// spec), numbers with a '.' decimal point whatever the C++ or C locale (std::to_chars). The C-angle
// list holds all Mc planes of the full circle; the intensity block holds only the planes the symmetry
// stores, in EULUMDAT order (Isym 3: C270..C345, C0..C90). Intensities are cd/klm.
#include <lumx/core/diagnostic.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/io/photometry_io.h>
#include <lumx/photometry/photometry.h>
#include <lumx/photometry/symmetry.h>

#include "io/text_scanner.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

LUMX_NAMESPACE_BEGIN

namespace {

[[noreturn]] void fail(const Photometry& p, const std::string& field, const std::string& message) {
  Diagnostic d;
  d.file = p.source.file;
  d.field = field;
  d.message = message;
  throw Error(std::move(d));
}

// Plain decimals with `digits` significant digits (never exponent notation, which EULUMDAT readers in
// the wild do not expect).
std::string num(double v, int digits) { return detail::format_number(v, digits); }

// Text fields must stay on one line: line breaks (e.g. from joined IES [MORE] keywords) become blanks.
std::string one_line(const std::string& s) {
  std::string out = s;
  for (char& c : out)
    if (c == '\r' || c == '\n') c = ' ';
  return out;
}

std::string keyword_or(const Photometry& p, const std::string& ldt_value, const char* keyword) {
  if (!ldt_value.empty()) return ldt_value;
  const Keyword* k = p.find_keyword(keyword);
  return k ? k->value : std::string();
}

bool uniform(const std::vector<double>& a, double& step) {
  step = 0;
  if (a.size() < 2) return false;
  step = a[1] - a[0];
  for (std::size_t i = 2; i < a.size(); ++i)
    if (std::abs((a[i] - a[i - 1]) - step) > 1e-9 * std::max(1.0, std::abs(step))) return false;
  return step > 0;
}

}  // namespace

std::string format_ldt(const Photometry& p, const LdtWriteOptions& options) {
  if (p.type != PhotometricType::C)
    fail(p, "photometric type",
         std::string("EULUMDAT holds Type C data only; this is Type ") + to_string(p.type) +
             " (convert with to_type_c first)");
  const std::size_t nh = p.horizontal_deg.size(), nv = p.vertical_deg.size();
  if (nh == 0 || nv == 0) fail(p, "angles", "no horizontal or no vertical angles");
  if (p.candela.size() != nh * nv)
    fail(p, "candela", "candela count " + std::to_string(p.candela.size()) + " != " + std::to_string(nh) + " x " +
                           std::to_string(nv));
  for (double v : p.candela)
    if (!std::isfinite(v)) fail(p, "candela", "non-finite candela value");
  for (double v : p.horizontal_deg)
    if (!std::isfinite(v)) fail(p, "horizontal angles", "non-finite angle");
  for (double v : p.vertical_deg)
    if (!std::isfinite(v)) fail(p, "vertical angles", "non-finite angle");
  const int digits = std::clamp(options.significant_digits, 1, 17);

  int isym = 0;
  switch (p.symmetry) {
    case Symmetry::none: isym = 0; break;
    case Symmetry::rotational: isym = 1; break;
    case Symmetry::plane_c0_c180: isym = 2; break;
    case Symmetry::plane_c90_c270: isym = 3; break;
    case Symmetry::quadrant: isym = 4; break;
    case Symmetry::lateral:
      fail(p, "symmetry", "lateral (Type A/B) symmetry has no EULUMDAT equivalent");
  }

  // Full circle: all planes in [0,360); a C360 plane is folded into C0 (see the intensity block below).
  AngleTable full;
  try {
    full = expand(stored_table(p), p.symmetry);
  } catch (const std::invalid_argument& e) {
    fail(p, "symmetry", e.what());
  }
  std::vector<double> call;
  for (double c : full.horizontal_deg) {
    if (c < 0 || c > 360) fail(p, "horizontal angles", "C angle " + num(c, digits) + " is outside 0..360");
    if (c == 360 && !call.empty() && call.front() == 0) continue;
    call.push_back(c);
  }
  if (isym == 1) call = {0.0};
  const std::size_t mc = call.size(), ng = nv;
  if (mc > 721) fail(p, "horizontal angles", std::to_string(mc) + " C-planes exceed the EULUMDAT limit of 721");
  if (ng > 361) fail(p, "vertical angles", std::to_string(ng) + " gamma angles exceed the EULUMDAT limit of 361");
  double dc = 0, dg = 0;
  if (mc > 1 && !(uniform(call, dc) && std::abs(dc * static_cast<double>(mc) - 360.0) < 1e-6)) dc = 0;
  if (mc == 1) dc = 0;
  if (!uniform(p.vertical_deg, dg)) dg = 0;

  // Model plane indices of the stored planes, in the order the file writes them.
  // Isym 3 stores C270..C90 wrapping: file plane f is the model plane 180 - f, i.e. reverse model order.
  // Isym 0 skips a C360 plane that repeats C0 (dropped from the C-angle list above as well).
  std::vector<std::size_t> order;
  order.reserve(nh);
  for (std::size_t i = 0; i < nh; ++i) {
    const std::size_t ih = isym == 3 ? nh - 1 - i : i;
    if (isym == 0 && p.horizontal_deg[ih] == 360 && p.horizontal_deg.front() == 0) continue;
    order.push_back(ih);
  }

  // Flux of the model (absolute cd), DFF and LOR.
  double flux = 0, down = 0;
  if (nv >= 2) {
    try {
      const IntensityTable table(p);
      flux = table.flux_lm();
      down = table.flux_lm(0, 90);
    } catch (const std::invalid_argument& e) {
      fail(p, "angles", e.what());
    }
  }

  if (!std::isfinite(flux) || !std::isfinite(down))
    fail(p, "candela", "the luminous flux of the table is not finite (intensities too large)");

  // Lamp sets. Absolute photometry (DIALux convention): negative count, and the flux field holds the
  // luminaire flux, to which the cd/klm values are relative. Relative: cd/klm per rated lamp flux.
  std::vector<LampSet> sets = p.lamp_sets;
  if (sets.empty()) sets.push_back(LampSet{});
  if (p.absolute) {
    double rated = 0;
    for (const auto& s : sets) rated += std::max(0.0, s.flux_lm);
    for (std::size_t i = 0; i < sets.size(); ++i) {
      sets[i].count = -std::max(1, std::abs(sets[i].count));
      // Split the luminaire flux in proportion to the sets' stated flux (all to the first if none).
      sets[i].flux_lm = rated > 0 ? flux * (std::max(0.0, sets[i].flux_lm) / rated) : (i == 0 ? flux : 0.0);
    }
  } else {
    for (auto& s : sets) s.count = std::abs(s.count);  // a negative count would mean absolute photometry
  }
  // The reader multiplies by the flux as written, so divide by the same rounded value: the intensity
  // round trip then loses only the rounding of the intensity itself.
  std::vector<std::string> flux_text(sets.size());
  double written_flux = 0;
  for (std::size_t i = 0; i < sets.size(); ++i) {
    flux_text[i] = num(sets[i].flux_lm, digits);
    double v = 0;
    detail::parse_number(flux_text[i], v);
    written_flux += v;
  }
  // Same rule as the reader: a total flux of 0 means the values are plain cd (1000 lm reference).
  const double scale = written_flux > 0 ? 1000.0 / written_flux : 1.0;
  double rated_total = 0;
  for (const auto& s : p.lamp_sets) rated_total += s.flux_lm;
  const double dff = flux > 0 ? 100.0 * (down / flux) : 0.0;
  double lor = p.absolute ? 100.0 : (rated_total > 0 ? 100.0 * (flux / rated_total) : 0.0);
  if (!std::isfinite(lor)) lor = 0;  // absurd rated flux (e.g. 1e-300 lm): state the LOR as unknown

  // Ityp: kept from an LDT source, else guessed from the symmetry and the opening's shape.
  int ityp = 3;
  if (p.source.format == "EULUMDAT" && p.ldt.ityp >= 0 && p.ldt.ityp <= 3) {
    ityp = p.ldt.ityp;
  } else if (isym == 1) {
    ityp = 1;
  } else if (std::abs(p.opening.length_m) > 2.0 * std::abs(p.opening.width_m)) {
    ityp = 2;
  }

  // Luminous area (mm): from the LDT header if stated, else from the opening (negative = round).
  const LdtHeader& h = p.ldt;
  double area_len = h.area_length_mm, area_wid = h.area_width_mm;
  double area_h[4] = {h.area_height_mm[0], h.area_height_mm[1], h.area_height_mm[2], h.area_height_mm[3]};
  const bool ldt_area = area_len != 0 || area_wid != 0 || area_h[0] != 0 || area_h[1] != 0 || area_h[2] != 0 ||
                        area_h[3] != 0;
  if (!ldt_area) {
    const LuminousOpening& o = p.opening;
    if (o.width_m < 0 || o.length_m < 0) {
      area_len = std::max(std::abs(o.width_m), std::abs(o.length_m)) * 1000.0;
      area_wid = 0;
    } else {
      area_len = o.length_m * 1000.0;
      area_wid = o.width_m * 1000.0;
    }
    for (double& v : area_h) v = std::abs(o.height_m) * 1000.0;
  }
  // Luminaire dimensions: from the header, else (IES has no separate luminaire size) the luminous area.
  double lum_len = h.luminaire_length_mm, lum_wid = h.luminaire_width_mm, lum_hgt = h.luminaire_height_mm;
  if (lum_len == 0 && lum_wid == 0 && lum_hgt == 0) {
    lum_len = area_len;
    lum_wid = area_wid;
    lum_hgt = area_h[0];
  }

  std::string out;
  out.reserve(64 * (60 + mc + ng) + 12 * nh * nv);
  auto line = [&](const std::string& s) {
    out += s;
    out += "\r\n";
  };
  auto number = [&](double v) { line(num(v, digits)); };

  line(one_line(keyword_or(p, h.company, "MANUFAC")));
  line(std::to_string(ityp));
  line(std::to_string(isym));
  line(std::to_string(mc));
  number(dc);
  line(std::to_string(ng));
  number(dg);
  line(one_line(keyword_or(p, h.report_number, "TEST")));
  line(one_line(keyword_or(p, h.luminaire_name, "LUMINAIRE")));
  line(one_line(keyword_or(p, h.luminaire_number, "LUMCAT")));
  line(one_line(h.file_name));
  line(one_line(keyword_or(p, h.date_user, "ISSUEDATE")));
  number(lum_len);
  number(lum_wid);
  number(lum_hgt);
  number(area_len);
  number(area_wid);
  for (double v : area_h) number(v);
  number(dff);
  number(lor);
  number(h.conversion_factor);
  number(h.tilt_deg);
  line(std::to_string(sets.size()));
  for (std::size_t i = 0; i < sets.size(); ++i) {
    const LampSet& s = sets[i];
    line(std::to_string(s.count));
    line(one_line(s.type));
    line(flux_text[i]);
    line(one_line(s.color));
    line(one_line(s.cri));
    number(s.watts);
  }
  for (std::size_t k = 0; k < 10; ++k) number(h.direct_ratios.size() == 10 ? h.direct_ratios[k] : 0.0);
  for (double c : call) number(c);
  for (double g : p.vertical_deg) number(g);
  // A model holding both C0 and C360 (IES without symmetry) may differ there; EULUMDAT has room for one
  // plane, so write their mean, which is what IntensityTable uses for that direction.
  const bool has_c360 = isym == 0 && nh > 1 && p.horizontal_deg.front() == 0 && p.horizontal_deg.back() == 360;
  for (std::size_t ih : order)
    for (std::size_t j = 0; j < nv; ++j) {
      const double cd = (has_c360 && ih == 0) ? 0.5 * (p.at(0, j) + p.at(nh - 1, j)) : p.at(ih, j);
      const double v = cd * scale;
      if (!std::isfinite(v)) fail(p, "lamp flux", "cd/klm overflow: lamp flux " + num(written_flux, digits) + " lm");
      number(v);
    }
  return out;
}

LUMX_NAMESPACE_END
