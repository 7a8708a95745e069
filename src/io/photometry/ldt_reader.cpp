// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// EULUMDAT (.ldt) reader (formats.md §2).
//
// Layout: lines 1-26 are a fixed header, one field per line; then 6 lines per lamp set; then the
// numeric part: 10 direct ratios, Mc C-angles, Ng gamma angles and the intensities (cd/klm) of the
// stored C-planes. The header and lamp sets are read line by line (their text fields may contain
// blanks). The numeric part is read as a whitespace-separated stream, so a writer that wraps several
// values onto one line is accepted too; one value per line is the special case. Commas are NOT
// delimiters in EULUMDAT: a comma is a decimal comma (see parse_real()).
//
// Policy (see also photometry_io.h): anything that would make the data wrong is an Error located by
// line and field; anything that merely disagrees with the spec but leaves the data unambiguous is a
// warning. Counts are checked against hard limits and against the number of values actually present
// before anything is allocated from them.
#include <lumx/core/diagnostic.h>
#include <lumx/io/photometry_io.h>
#include <lumx/photometry/photometry.h>
#include <lumx/version.h>

#include "io/photometry/intensity_checks.h"
#include "io/text_scanner.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

LUMX_NAMESPACE_BEGIN

namespace {

// Hard EULUMDAT limits (formats.md §2.1, hard-cases.md §6 #12): at most 721 C-planes (0.5 degree steps
// over the circle) and 361 gamma angles (0.5 degree steps over 0..180).
constexpr int kMaxCPlanes = 721;
constexpr int kMaxGamma = 361;

/// Which bound an out-of-range count met: the format's own, or the embedder's option (named, so that it
/// knows what to raise).
std::string limit_source(std::size_t format_bound, std::size_t option, const char* option_name,
                         const char* fixed = "the EULUMDAT maximum") {
  return option < format_bound ? std::string(" (") + option_name + " is " + std::to_string(option) + ")"
                               : std::string(" (") + fixed + ")";
}

// Header line numbers (1-based) of the fixed fields.
enum HeaderLine : int {
  kCompany = 1, kItyp = 2, kIsym = 3, kMc = 4, kDc = 5, kNg = 6, kDg = 7,
  kReport = 8, kLumName = 9, kLumNumber = 10, kFileName = 11, kDateUser = 12,
  kLumLength = 13, kLumWidth = 14, kLumHeight = 15, kAreaLength = 16, kAreaWidth = 17,
  kAreaHeightC0 = 18, kDff = 22, kLorl = 23, kConversion = 24, kTilt = 25, kLampSetCount = 26,
};

// Short, locale-independent rendering for messages (std::to_string would print 6 decimals).
std::string fmt(double v) { return detail::format_number(v, 10); }

bool is_digit(char c) { return c >= '0' && c <= '9'; }

class LdtParser {
 public:
  LdtParser(std::string_view text, const std::string& name, const ReadOptions& options)
      : text_(text), name_(name), opt_(options), cursor_(text) {}

  Photometry parse();

 private:
  [[noreturn]] void fail(int line, const std::string& field, const std::string& message) const {
    throw_at_line(name_, line, field, message);
  }

  void warn(int line, const std::string& field, const std::string& message) const {
    if (!opt_.warnings) return;
    Diagnostic d;
    d.severity = Severity::warning;
    d.file = name_;
    d.line = line;
    d.field = field;
    d.message = message;
    opt_.warnings(d);
  }

  // The trimmed text of header line `n` (1-based); error if the file ends before it.
  std::string_view line_text(int n, const std::string& field) const {
    if (n >= 1) ensure_lines(static_cast<std::size_t>(n));
    if (n < 1 || static_cast<std::size_t>(n) > lines_.size())
      fail(n, field, "file ends before this field (line " + std::to_string(n) + "; the file has " +
                         std::to_string(lines_.size()) + " lines)");
    return detail::trim(lines_[static_cast<std::size_t>(n - 1)].text);
  }

  std::string text_field(int n, const std::string& field) const { return detail::to_utf8(line_text(n, field)); }

  double real_field(int n, const std::string& field) const { return parse_real(line_text(n, field), n, field); }

  int int_field(int n, const std::string& field) const { return parse_int(line_text(n, field), n, field); }

  double parse_real(std::string_view tok, int line, const std::string& field) const;
  int parse_int(std::string_view tok, int line, const std::string& field) const;

  // Splits lines [first_index, end) into whitespace-separated tokens (NOT commas: decimal commas).
  // Keeps at most `keep` tokens (the count the header implies) and only counts the rest, so memory is
  // bounded by the header's (already limited) counts, not by the file size.
  void tokenize_numeric(std::size_t first_index, std::size_t keep);

  std::string_view text_;
  const std::string& name_;
  const ReadOptions& opt_;
  // Header lines are split on demand, so only the (at most ~160) header lines are ever stored; the
  // numeric part is tokenised straight from the cursor.
  void ensure_lines(std::size_t n) const {
    detail::Line l;
    while (lines_.size() < n && cursor_.next(l)) lines_.push_back(l);
  }

  mutable detail::LineCursor cursor_;
  mutable std::vector<detail::Line> lines_;
  std::vector<detail::Token> tokens_;
  std::size_t extra_tokens_ = 0;  // tokens beyond `keep`
  int first_extra_line_ = 0;
};

// A real number, with a decimal point or a decimal comma ("0,85"). A comma is ambiguous, and refused,
// when it could just as well be a thousands separator: "1,000" is 1.0 to a decimal-comma writer and
// 1000 to an English-locale one, and a misread changes the value a thousandfold, so we do not guess. The
// comma is taken as a possible thousands separator when it is followed by exactly three digits and
// preceded by one to three digits that do not start with 0 (a thousands group never follows a leading
// zero, so "0,850" is unambiguously 0.85). A token with several commas, or a comma and a point, is
// refused too. NaN and infinities are refused (parse_number never accepts them).
double LdtParser::parse_real(std::string_view tok, int line, const std::string& field) const {
  tok = detail::trim(tok);
  if (tok.empty()) fail(line, field, "empty, expected a number");
  const std::size_t comma = tok.find(',');
  std::string buf;
  if (comma != std::string_view::npos) {
    if (tok.find(',', comma + 1) != std::string_view::npos || tok.find('.') != std::string_view::npos)
      fail(line, field, "'" + detail::excerpt(tok) + "' mixes decimal and grouping separators; ambiguous number");
    std::string_view before = tok.substr(0, comma), after = tok.substr(comma + 1);
    if (!before.empty() && (before.front() == '-' || before.front() == '+')) before.remove_prefix(1);
    const bool three_after = after.size() == 3 && std::all_of(after.begin(), after.end(), is_digit);
    const bool group_before = !before.empty() && before.size() <= 3 && before.front() != '0' &&
                              std::all_of(before.begin(), before.end(), is_digit);
    if (three_after && group_before)
      fail(line, field,
           "'" + detail::excerpt(tok) +
               "' is ambiguous: the comma may be a decimal comma or a thousands separator");
    buf.assign(tok.data(), tok.size());
    buf[comma] = '.';
    tok = buf;
  }
  double v = 0;
  if (!detail::parse_number(tok, v)) fail(line, field, "'" + detail::excerpt(tok) + "' is not a finite number");
  return v;
}

// An integer field (Ityp, Isym, Mc, Ng, number of lamp sets, lamp count). Only an optional sign and
// digits are accepted, plus an all-zero fraction ("24.0") that some writers emit: the value is then
// still exactly an integer. "3.7" (would need truncation), "1e10" (exponent form) and "nan" are errors.
int LdtParser::parse_int(std::string_view tok, int line, const std::string& field) const {
  tok = detail::trim(tok);
  if (tok.empty()) fail(line, field, "empty, expected an integer");
  const std::string shown = detail::excerpt(tok);
  bool negative = false;
  if (tok.front() == '-' || tok.front() == '+') {
    negative = tok.front() == '-';
    tok.remove_prefix(1);
  }
  std::size_t i = 0;
  while (i < tok.size() && is_digit(tok[i])) ++i;
  const std::string_view digits = tok.substr(0, i);
  if (digits.empty()) fail(line, field, "'" + shown + "' is not an integer");
  if (i < tok.size()) {
    const std::string_view frac = tok.substr(i + 1);
    const bool zero_fraction = (tok[i] == '.' || tok[i] == ',') && !frac.empty() &&
                               std::all_of(frac.begin(), frac.end(), [](char c) { return c == '0'; });
    // "1,000" in an integer field is as ambiguous as in a real one (1 or 1000).
    if (!zero_fraction || (tok[i] == ',' && frac.size() == 3))
      fail(line, field, "'" + shown + "' is not an integer");
  }
  std::size_t first = 0;
  while (first + 1 < digits.size() && digits[first] == '0') ++first;
  if (digits.size() - first > 9) fail(line, field, "'" + shown + "' is out of range");
  long v = 0;
  for (std::size_t k = first; k < digits.size(); ++k) v = v * 10 + (digits[k] - '0');
  return static_cast<int>(negative ? -v : v);
}

void LdtParser::tokenize_numeric(std::size_t first_index, std::size_t keep) {
  ensure_lines(first_index);
  detail::Line next;
  for (std::size_t li = first_index; li < lines_.size() || cursor_.next(next); ++li) {
    const detail::Line& line = li < lines_.size() ? lines_[li] : next;
    const std::string_view s = line.text;
    std::size_t i = 0;
    auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\0' || c == '\f' || c == '\v'; };
    while (i < s.size()) {
      while (i < s.size() && blank(s[i])) ++i;
      const std::size_t b = i;
      while (i < s.size() && !blank(s[i])) ++i;
      if (i == b) continue;
      if (tokens_.size() < keep) {
        tokens_.push_back({s.substr(b, i - b), line.number});
      } else if (extra_tokens_++ == 0) {
        first_extra_line_ = line.number;
      }
    }
  }
}

Photometry LdtParser::parse() {
  if (text_.size() > opt_.limits.max_file_bytes) {
    Diagnostic d;
    d.file = name_;
    d.byte_offset = static_cast<std::int64_t>(opt_.limits.max_file_bytes);
    d.field = "file size";
    d.message = "file of " + std::to_string(text_.size()) + " bytes exceeds ReadLimits::max_file_bytes (" +
                std::to_string(opt_.limits.max_file_bytes) + ")";
    throw Error(std::move(d));
  }

  Photometry p;
  p.type = PhotometricType::C;
  p.source.file = name_;
  p.source.format = "EULUMDAT";
  p.source.version = file_format::kEulumdat;
  LdtHeader& h = p.ldt;

  // ---- fixed header, lines 1..26 ----
  h.company = text_field(kCompany, "company");
  h.ityp = int_field(kItyp, "Ityp");
  if (h.ityp < 0 || h.ityp > 3)
    fail(kItyp, "Ityp", "type indicator " + std::to_string(h.ityp) + " is not 0, 1, 2 or 3");
  const int isym = int_field(kIsym, "Isym");
  if (isym < 0 || isym > 4) fail(kIsym, "Isym", "symmetry indicator " + std::to_string(isym) + " is not 0..4");
  static constexpr Symmetry kSym[5] = {Symmetry::none, Symmetry::rotational, Symmetry::plane_c0_c180,
                                       Symmetry::plane_c90_c270, Symmetry::quadrant};
  p.symmetry = kSym[isym];
  if ((h.ityp == 1) != (isym == 1))
    warn(kIsym, "Isym",
         "Isym " + std::to_string(isym) + " is inconsistent with Ityp " + std::to_string(h.ityp) +
             " (1 = rotationally symmetric point source); Isym is used");

  const int mc = int_field(kMc, "Mc");
  const int mc_limit = static_cast<int>(std::min<std::size_t>(kMaxCPlanes, opt_.limits.max_angles));
  if (mc < 1 || mc > mc_limit)
    fail(kMc, "Mc", "number of C-planes " + std::to_string(mc) + " is outside 1.." + std::to_string(mc_limit) +
                        limit_source(kMaxCPlanes, opt_.limits.max_angles, "ReadLimits::max_angles"));
  const double dc = real_field(kDc, "Dc");
  if (dc < 0) fail(kDc, "Dc", "C-plane spacing " + fmt(dc) + " is negative");
  const int ng = int_field(kNg, "Ng");
  const int ng_limit = static_cast<int>(std::min<std::size_t>(kMaxGamma, opt_.limits.max_angles));
  if (ng < 2 || ng > ng_limit)  // one gamma angle describes no solid angle: no flux, no interpolation
    fail(kNg, "Ng", "number of gamma angles " + std::to_string(ng) + " is outside 2.." + std::to_string(ng_limit) +
                        limit_source(kMaxGamma, opt_.limits.max_angles, "ReadLimits::max_angles"));
  const double dg = real_field(kDg, "Dg");
  if (dg < 0) fail(kDg, "Dg", "gamma spacing " + fmt(dg) + " is negative");

  // Number of stored C-planes per Isym (formats.md §2.2).
  const int divisor = (isym == 2 || isym == 3) ? 2 : (isym == 4 ? 4 : 1);
  if (mc % divisor != 0) {
    // Suggest counts that would load: for Isym 3 on a uniform grid only multiples of 4 have the C90 and
    // C270 planes it stores from and to, so suggest those (an even Mc not divisible by 4 needs a
    // non-uniform, mirror-symmetric angle list).
    const int step = isym == 3 ? 4 : divisor;
    const int lo = mc / step * step, hi = lo + step;
    const std::string stored = isym == 4 ? "Mc/4+1" : "Mc/2+1";
    std::string expected = lo > 0 ? "Mc = " + std::to_string(lo) + " (" + std::to_string(lo / divisor + 1) +
                                        " stored planes) or "
                                  : std::string("Mc = ");
    expected += (lo > 0 ? "Mc = " : "") + std::to_string(hi) + " (" + std::to_string(hi / divisor + 1) +
                " stored planes)";
    fail(kMc, "Mc",
         "Isym " + std::to_string(isym) + " stores " + stored + " C-planes, so Mc must be a multiple of " +
             std::to_string(divisor) + "; got Mc = " + std::to_string(mc) + ", expected e.g. " + expected);
  }
  std::size_t nstored = 0;
  switch (isym) {
    case 0: nstored = static_cast<std::size_t>(mc); break;
    case 1: nstored = 1; break;
    case 2:
    case 3: nstored = static_cast<std::size_t>(mc / 2 + 1); break;
    default: nstored = static_cast<std::size_t>(mc / 4 + 1); break;
  }
  if (isym == 4 && mc < 4) fail(kMc, "Mc", "Isym 4 needs Mc >= 4 (C0 and C90 planes)");
  if ((isym == 2 || isym == 3) && mc < 2)
    fail(kMc, "Mc", "Isym " + std::to_string(isym) + " needs Mc >= 2");

  h.report_number = text_field(kReport, "report number");
  h.luminaire_name = text_field(kLumName, "luminaire name");
  h.luminaire_number = text_field(kLumNumber, "luminaire number");
  h.file_name = text_field(kFileName, "file name");
  h.date_user = text_field(kDateUser, "date/user");
  h.luminaire_length_mm = real_field(kLumLength, "luminaire length");
  h.luminaire_width_mm = real_field(kLumWidth, "luminaire width");
  h.luminaire_height_mm = real_field(kLumHeight, "luminaire height");
  h.area_length_mm = real_field(kAreaLength, "luminous area length");
  h.area_width_mm = real_field(kAreaWidth, "luminous area width");
  static const char* const kHeightNames[4] = {"luminous area height C0", "luminous area height C90",
                                              "luminous area height C180", "luminous area height C270"};
  for (int k = 0; k < 4; ++k) h.area_height_mm[k] = real_field(kAreaHeightC0 + k, kHeightNames[k]);
  h.dff_percent = real_field(kDff, "DFF");
  h.lor_percent = real_field(kLorl, "LORL");
  h.conversion_factor = real_field(kConversion, "conversion factor");
  // The conversion factor is kept but NOT applied: the readers that apply it (alwan) and those that do
  // not disagree (formats.md §2.3), DIALux-exported files always write 1, and the cd/klm x lamp-flux
  // scaling already gives absolute candela. A value other than 1 is reported so the caller can decide.
  if (h.conversion_factor != 1.0)
    warn(kConversion, "conversion factor",
         "conversion factor " + fmt(h.conversion_factor) + " is not 1; it is kept in the header but not applied");
  h.tilt_deg = real_field(kTilt, "tilt");

  const int nsets = int_field(kLampSetCount, "number of lamp sets");
  const int sets_limit = static_cast<int>(std::min<std::size_t>(opt_.limits.max_lamp_sets, 100000));
  if (nsets < 1 || nsets > sets_limit)
    fail(kLampSetCount, "number of lamp sets",
         std::to_string(nsets) + " lamp sets is outside 1.." + std::to_string(sets_limit) +
             limit_source(100000, opt_.limits.max_lamp_sets, "ReadLimits::max_lamp_sets", "lumx's fixed bound"));

  // ---- lamp sets, 6 lines each ----
  double sum_flux = 0, sum_watts = 0;
  int flux_line = kLampSetCount + 3;
  for (int s = 0; s < nsets; ++s) {
    const int base = kLampSetCount + 1 + 6 * s;
    const std::string tag = "lamp set " + std::to_string(s + 1) + " ";
    LampSet ls;
    ls.count = int_field(base, tag + "lamp count");
    ls.type = text_field(base + 1, tag + "lamp type");
    ls.flux_lm = real_field(base + 2, tag + "luminous flux");
    if (ls.flux_lm < 0) fail(base + 2, tag + "luminous flux", "negative flux " + fmt(ls.flux_lm));
    ls.color = text_field(base + 3, tag + "colour appearance");
    ls.cri = text_field(base + 4, tag + "colour rendering group");
    ls.watts = real_field(base + 5, tag + "wattage");
    if (ls.count < 0) p.absolute = true;  // DIALux convention: negative count = absolute photometry
    sum_flux += ls.flux_lm;
    sum_watts += ls.watts;
    if (s == 0) flux_line = base + 2;
    p.lamp_sets.push_back(std::move(ls));
  }
  p.input_watts = sum_watts;
  if (!std::isfinite(sum_flux))
    fail(flux_line, "lamp set 1 luminous flux", "total lamp flux overflows (" + fmt(sum_flux) + ")");

  // ---- numeric stream: direct ratios, C angles, gamma angles, intensities ----
  const std::size_t numeric_start = static_cast<std::size_t>(kLampSetCount + 6 * nsets);  // 0-based index
  const std::size_t ncs = static_cast<std::size_t>(mc), ngs = static_cast<std::size_t>(ng);
  const std::size_t needed = 10 + ncs + ngs + nstored * ngs;  // <= 10 + 721 + 361 + 721 * 361
  ensure_lines(numeric_start);
  tokenize_numeric(std::min(numeric_start, lines_.size()), needed);
  std::size_t pos = 0;
  // Field name of the k-th value of the numeric stream, for messages.
  auto field_of = [&](std::size_t k) -> std::string {
    if (k < 10) return "direct ratio " + std::to_string(k + 1);
    k -= 10;
    if (k < ncs) return "C angle " + std::to_string(k + 1);
    k -= ncs;
    if (k < ngs) return "gamma angle " + std::to_string(k + 1);
    k -= ngs;
    return "intensity " + std::to_string(k + 1) + " (stored plane " + std::to_string(k / ngs + 1) +
           ", gamma index " + std::to_string(k % ngs + 1) + ")";
  };
  if (tokens_.size() < needed) {
    // Truncated: name the first missing value and the line where it should have been.
    const int last_line = tokens_.empty() ? static_cast<int>(numeric_start) : tokens_.back().line;
    fail(last_line + 1, field_of(tokens_.size()),
         "file ends early: " + std::to_string(needed) + " numeric values expected after the lamp sets (10 direct "
         "ratios, " + std::to_string(mc) + " C angles, " + std::to_string(ng) + " gamma angles, " +
         std::to_string(nstored) + " x " + std::to_string(ng) + " intensities), found " +
         std::to_string(tokens_.size()));
  }
  auto next = [&](double& v) -> int {
    const detail::Token& t = tokens_[pos];
    v = parse_real(t.text, t.line, field_of(pos));
    ++pos;
    return t.line;
  };

  h.direct_ratios.resize(10);
  for (double& r : h.direct_ratios) next(r);

  std::vector<double> cang(ncs);
  std::vector<std::uint32_t> cline(ncs);
  for (std::size_t i = 0; i < ncs; ++i) {
    const int ln = next(cang[i]);
    cline[i] = static_cast<std::uint32_t>(ln);
    if (cang[i] < 0 || cang[i] > 360)
      fail(ln, "C angle " + std::to_string(i + 1), "C angle " + fmt(cang[i]) + " is outside 0..360");
    if (i > 0 && !(cang[i] > cang[i - 1]))
      fail(ln, "C angle " + std::to_string(i + 1),
           "C angles are not strictly increasing (" + fmt(cang[i - 1]) + " then " + fmt(cang[i]) + ")");
  }
  std::vector<double> gang(ngs);
  std::vector<std::uint32_t> gline(ngs);
  for (std::size_t i = 0; i < ngs; ++i) {
    const int ln = next(gang[i]);
    gline[i] = static_cast<std::uint32_t>(ln);
    if (gang[i] < 0 || gang[i] > 180)
      fail(ln, "gamma angle " + std::to_string(i + 1), "gamma angle " + fmt(gang[i]) + " is outside 0..180");
    if (i > 0 && !(gang[i] > gang[i - 1]))
      fail(ln, "gamma angle " + std::to_string(i + 1),
           "gamma angles are not strictly increasing (" + fmt(gang[i - 1]) + " then " + fmt(gang[i]) + ")");
  }

  // Dc/Dg = 0 means non-equidistant angles; the explicit lists are always what is used. A non-zero
  // spacing that disagrees with the list is only reported.
  auto check_spacing = [&](const std::vector<double>& a, double d, int line, const char* field, const char* what) {
    if (d == 0 || a.size() < 2) return;
    for (std::size_t i = 1; i < a.size(); ++i) {
      if (std::abs(a[i] - (a[0] + static_cast<double>(i) * d)) > 1e-3) {
        warn(line, field,
             std::string(what) + " spacing " + fmt(d) + " disagrees with the listed angles (" + fmt(a[i - 1]) +
                 ", " + fmt(a[i]) + "); the listed angles are used");
        return;
      }
    }
  };
  if (isym != 1) check_spacing(cang, dc, kDc, "Dc", "C-plane");
  check_spacing(gang, dg, kDg, "Dg", "gamma");

  // Which file planes are stored (file order), and the model angle of each.
  // Isym 3 stores C270..C345, C0..C90 (wrapping); the model keeps the IES range [90,270], so each file
  // plane f becomes the model plane c = (180 - f) mod 360 (the mirror image about the C90-C270 plane,
  // which the symmetry says holds the same values). The model order is then the reverse file order.
  auto near = [](double a, double b) { return std::abs(a - b) < 1e-6; };
  std::vector<std::size_t> stored_index(nstored);
  std::vector<double> model_angle(nstored);
  switch (isym) {
    case 0:
      for (std::size_t i = 0; i < nstored; ++i) stored_index[i] = i, model_angle[i] = cang[i];
      break;
    case 1:
      stored_index[0] = 0;
      model_angle[0] = 0;
      break;
    case 2:
    case 4: {
      const double last = isym == 2 ? 180.0 : 90.0;
      if (!near(cang[0], 0))
        fail(static_cast<int>(cline[0]), "C angle 1",
             "Isym " + std::to_string(isym) + " stores planes from C0, but the first C angle is " + fmt(cang[0]));
      if (!near(cang[nstored - 1], last))
        fail(static_cast<int>(cline[nstored - 1]), "C angle " + std::to_string(nstored),
             "Isym " + std::to_string(isym) + " stores C0..C" + fmt(last) + " (" + std::to_string(nstored) +
                 " planes), but stored plane " + std::to_string(nstored) + " is C" + fmt(cang[nstored - 1]));
      for (std::size_t i = 0; i < nstored; ++i) stored_index[i] = i, model_angle[i] = cang[i];
      break;
    }
    default: {  // 3
      std::size_t k270 = ncs;
      for (std::size_t i = 0; i < ncs; ++i)
        if (near(cang[i], 270)) k270 = i;
      if (k270 == ncs)
        fail(static_cast<int>(cline[0]), "C angles", "Isym 3 stores C270..C90, but there is no C270 plane");
      for (std::size_t i = 0; i < nstored; ++i) stored_index[i] = (k270 + i) % ncs;
      const std::size_t k_last = stored_index[nstored - 1];
      if (!near(cang[k_last], 90) || (k270 + nstored - 1) < ncs)
        fail(static_cast<int>(cline[k_last]), "C angle " + std::to_string(k_last + 1),
             "Isym 3 stores " + std::to_string(nstored) + " planes from C270 wrapping to C90, but the last one is C" +
                 fmt(cang[k_last]));
      for (std::size_t i = 0; i < nstored; ++i) {
        const double f = cang[stored_index[i]];
        model_angle[i] = f >= 270.0 ? 540.0 - f : 180.0 - f;
      }
      break;
    }
  }

  // Intensities: cd/klm of lamp flux -> absolute cd. For absolute photometry the flux field holds the
  // luminaire's flux (DIALux), and the same formula applies.
  double klm = sum_flux / 1000.0;
  if (!(sum_flux > 0)) {
    warn(flux_line, "lamp set 1 luminous flux",
         "total lamp flux is 0; intensities are taken as cd (as if the lamps gave 1000 lm)");
    klm = 1.0;
  }
  p.horizontal_deg.resize(nstored);
  p.source.horizontal_lines.resize(nstored);
  p.vertical_deg = gang;
  p.source.vertical_lines = gline;
  p.candela.resize(nstored * ngs);
  p.source.candela_lines.resize(nstored * ngs);
  for (std::size_t fp = 0; fp < nstored; ++fp) {
    const std::size_t mp = isym == 3 ? nstored - 1 - fp : fp;  // model plane index
    p.horizontal_deg[mp] = model_angle[fp];
    p.source.horizontal_lines[mp] = cline[stored_index[fp]];
    for (std::size_t j = 0; j < ngs; ++j) {
      double v = 0;
      const int ln = next(v);
      p.candela[mp * ngs + j] = v * klm;
      if (!std::isfinite(p.candela[mp * ngs + j]))
        fail(ln, field_of(pos - 1), "intensity " + fmt(v) + " cd/klm x " + fmt(klm) + " klm overflows");
      p.source.candela_lines[mp * ngs + j] = static_cast<std::uint32_t>(ln);
    }
  }
  // Negative intensities: the readers' shared policy (io/intensity_checks.h).
  const detail::NegativeIntensities neg = detail::find_negative_intensities(p.candela, p.source.candela_lines);
  if (neg.bad != SIZE_MAX)
    fail(static_cast<int>(p.source.candela_lines[neg.bad]),
         "intensity (C" + fmt(p.horizontal_deg[neg.bad / ngs]) + ", gamma " + fmt(p.vertical_deg[neg.bad % ngs]) + ")",
         "negative intensity " + fmt(p.candela[neg.bad] / klm) + " cd/klm exceeds 0.1 % of the peak " +
             fmt(neg.peak / klm) + " cd/klm");
  if (neg.count > 0)
    warn(neg.first_line, "intensity",
         std::to_string(neg.count) + " small negative intensity value(s) (measurement noise, <= 0.1 % of peak) kept");

  if (extra_tokens_ > 0)
    warn(first_extra_line_, "trailing data",
         std::to_string(extra_tokens_) + " value(s) after the last intensity are ignored");

  // Luminous opening from the luminous area (mm -> m). A width of 0 means a circular area whose
  // diameter is the length; LM-63 writes a circle as negative width and length.
  const double area_len = h.area_length_mm / 1000.0, area_wid = h.area_width_mm / 1000.0;
  if (h.area_width_mm == 0 && h.area_length_mm != 0) {
    p.opening.length_m = p.opening.width_m = -std::abs(area_len);
  } else {
    p.opening.length_m = area_len;
    p.opening.width_m = area_wid;
  }
  p.opening.height_m =
      (h.area_height_mm[0] + h.area_height_mm[1] + h.area_height_mm[2] + h.area_height_mm[3]) / 4.0 / 1000.0;
  return p;
}

}  // namespace

Photometry read_ldt(std::string_view text, const std::string& name, const ReadOptions& options) {
  LdtParser parser(text, name, options);
  return parser.parse();
}

LUMX_NAMESPACE_END
