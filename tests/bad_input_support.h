// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Helpers shared by tests/test_bad_input_ies.cpp and tests/test_bad_input_ldt.cpp: the bad-input corpus
// in tests/data/bad (regenerate with tests/data/bad/make_corpus.py), locating text in it by line, checking
// the located-error contract of lumx::Error, and the "never crash" sweep.
#pragma once

#include "test_support.h"

#include <lumx/core/diagnostic.h>
#include <lumx/io/photometry_io.h>
#include <lumx/photometry/photometry.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace lumx_bad {

inline std::filesystem::path bad_dir() { return lumx_test::data_dir() / "bad"; }

/// Bytes of a corpus file (fails the test if it is missing).
inline std::string corpus(const std::string& name) {
  const auto p = bad_dir() / name;
  if (!std::filesystem::exists(p)) ADD_FAILURE() << "missing corpus file " << p;
  return lumx_test::read_text(p);
}

/// 1-based line of byte `pos`; LF, CRLF and a lone CR each end a line.
inline int line_at(std::string_view text, std::size_t pos) {
  int line = 1;
  for (std::size_t i = 0; i < pos && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
    } else if (text[i] == '\r' && (i + 1 >= text.size() || text[i + 1] != '\n')) {
      ++line;
    }
  }
  return line;
}

/// 1-based line of the first occurrence of `needle` (0 if absent, which fails the test).
inline int line_of(std::string_view text, std::string_view needle) {
  const auto pos = text.find(needle);
  if (pos == std::string_view::npos) {
    ADD_FAILURE() << "corpus text lacks '" << needle << "'";
    return 0;
  }
  return line_at(text, pos);
}

/// Number of the last line that holds something other than blanks.
inline int last_content_line(std::string_view text) {
  std::size_t end = text.find_last_not_of(" \t\r\n");
  if (end == std::string_view::npos) return 0;
  return line_at(text, end);
}

/// Runs `f`, which must throw lumx::Error. Returns its diagnostic; records a failure (and returns
/// nullopt) if it returns normally or throws anything else.
template <class F>
std::optional<lumx::Diagnostic> catch_error(F&& f) {
  try {
    f();
  } catch (const lumx::Error& e) {
    return e.diagnostic();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "threw a non-lumx exception: " << e.what();
    return std::nullopt;
  } catch (...) {
    ADD_FAILURE() << "threw something that is not a std::exception";
    return std::nullopt;
  }
  ADD_FAILURE() << "loaded without an error";
  return std::nullopt;
}

/// The E contract: located by file (the name passed), a line > 0 (one of `lines` when given) and a
/// non-empty field name.
inline void expect_located(const std::optional<lumx::Diagnostic>& d, const std::string& file,
                           const std::vector<int>& lines = {}) {
  if (!d) return;  // catch_error already failed the test
  EXPECT_EQ(d->file, file) << d->str();
  EXPECT_GT(d->line, 0) << d->str();
  EXPECT_FALSE(d->field.empty()) << d->str();
  EXPECT_FALSE(d->message.empty()) << d->str();
  EXPECT_EQ(d->severity, lumx::Severity::error) << d->str();
  if (!lines.empty()) {
    std::ostringstream want;
    for (int l : lines) want << l << ' ';
    EXPECT_NE(std::find(lines.begin(), lines.end(), d->line), lines.end())
        << "expected the error on line " << want.str() << "but got: " << d->str();
  }
}

/// Options whose warning sink appends to `list`.
inline lumx::ReadOptions collecting(lumx::DiagnosticList& list) {
  lumx::ReadOptions o;
  o.warnings = list.sink();
  return o;
}

inline std::size_t count_warnings(const lumx::DiagnosticList& list) {
  return static_cast<std::size_t>(std::count_if(list.items.begin(), list.items.end(), [](const auto& d) {
    return d.severity == lumx::Severity::warning;
  }));
}

inline std::string dump(const lumx::DiagnosticList& list) {
  std::string s;
  for (const auto& d : list.items) s += "  " + d.str() + "\n";
  return s;
}

// ---- never-crash sweep -----------------------------------------------------------------------------

/// splitmix64: a fixed, platform-independent pseudo-random sequence (std distributions are not).
struct SplitMix64 {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  std::size_t below(std::size_t n) { return n ? static_cast<std::size_t>(next() % n) : 0; }
};

/// ~`count` deterministic corruptions of `good`: bit flips, replacement by bytes that matter to a
/// number parser or a line splitter, and insertion of hostile tokens.
inline std::vector<std::string> mutations(const std::string& good, std::uint64_t seed, int count) {
  static const char kBytes[] = {'-', '+', '9', '0', '.', ',', 'e', 'E', 'n', 'i', ' ', '\t', '\n', '\r', '\0',
                                '\x7f', '\xff', '\xb0', '[', '='};
  static const char* const kTokens[] = {"2147483647", "-1",  "1e308", "-1e308", "nan",   "inf",
                                        "4294967296", "1e-320", "0",  "TILT=INCLUDE\n", "\n\n\n", "99999"};
  SplitMix64 rng{seed};
  std::vector<std::string> out;
  out.reserve(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) {
    std::string s = good;
    const std::size_t pos = rng.below(s.size());
    switch (rng.below(4)) {
      case 0: s[pos] = static_cast<char>(s[pos] ^ (1u << rng.below(8))); break;
      case 1: s[pos] = kBytes[rng.below(sizeof kBytes)]; break;
      case 2: s.insert(pos, kTokens[rng.below(sizeof kTokens / sizeof kTokens[0])]); break;
      default: {  // replace a whole number-ish run with a hostile token
        std::size_t b = pos, e = pos;
        auto numch = [](char c) { return std::isdigit(static_cast<unsigned char>(c)) || c == '.' || c == '-'; };
        while (b > 0 && numch(s[b - 1])) --b;
        while (e < s.size() && numch(s[e])) ++e;
        s.replace(b, e - b, kTokens[rng.below(sizeof kTokens / sizeof kTokens[0])]);
        break;
      }
    }
    out.push_back(std::move(s));
  }
  return out;
}

/// Calls `read` on `input`: it must either return a consistent, finite Photometry or throw lumx::Error.
/// Returns false (after recording a failure naming `what`) otherwise.
inline bool loads_sanely_or_errors(const std::function<lumx::Photometry(const std::string&)>& read,
                                   const std::string& input, const std::string& what) {
  try {
    const lumx::Photometry p = read(input);
    if (p.candela.size() != p.horizontal_deg.size() * p.vertical_deg.size()) {
      ADD_FAILURE() << what << ": candela count " << p.candela.size() << " != " << p.horizontal_deg.size()
                    << " x " << p.vertical_deg.size();
      return false;
    }
    for (double v : p.candela)
      if (!std::isfinite(v)) {
        ADD_FAILURE() << what << ": non-finite candela " << v;
        return false;
      }
    for (double v : p.horizontal_deg)
      if (!std::isfinite(v)) {
        ADD_FAILURE() << what << ": non-finite horizontal angle";
        return false;
      }
    for (double v : p.vertical_deg)
      if (!std::isfinite(v)) {
        ADD_FAILURE() << what << ": non-finite vertical angle";
        return false;
      }
    return true;
  } catch (const lumx::Error&) {
    return true;
  } catch (const std::exception& e) {
    ADD_FAILURE() << what << ": threw a non-lumx exception: " << e.what();
    return false;
  } catch (...) {
    ADD_FAILURE() << what << ": threw something that is not a std::exception";
    return false;
  }
}

/// Truncation at every byte offset, then `n_mutations` corruptions; stops reporting after 10 failures.
inline void never_crash_sweep(const std::function<lumx::Photometry(const std::string&)>& read,
                              const std::string& good, const std::string& name, std::uint64_t seed,
                              int n_mutations = 200) {
  int failures = 0;
  for (std::size_t n = 0; n <= good.size() && failures < 10; ++n)
    if (!loads_sanely_or_errors(read, good.substr(0, n), name + " truncated to " + std::to_string(n) + " bytes"))
      ++failures;
  const auto muts = mutations(good, seed, n_mutations);
  for (std::size_t k = 0; k < muts.size() && failures < 10; ++k)
    if (!loads_sanely_or_errors(read, muts[k], name + " mutation #" + std::to_string(k))) ++failures;
}

/// Every numeric token of `good` (a maximal run of digits, '.', '+', '-', 'e', 'E' that holds a digit)
/// replaced in turn by each hostile token: catches what random corruption rarely hits, such as a
/// candela multiplier of 1e308 that overflows the table to inf.
inline void token_sweep(const std::function<lumx::Photometry(const std::string&)>& read, const std::string& good,
                        const std::string& name) {
  static const char* const kTokens[] = {"2147483647", "-2147483648", "-1", "0", "1e308", "-1e308", "1e-320",
                                        "nan", "inf", "4294967297", "1.5", "99999", "1,5", ""};
  auto numch = [](char c) {
    return std::isdigit(static_cast<unsigned char>(c)) || c == '.' || c == '+' || c == '-' || c == 'e' || c == 'E';
  };
  int failures = 0;
  for (std::size_t b = 0; b < good.size() && failures < 10;) {
    if (!numch(good[b])) {
      ++b;
      continue;
    }
    std::size_t e = b;
    bool digit = false;
    for (; e < good.size() && numch(good[e]); ++e)
      if (std::isdigit(static_cast<unsigned char>(good[e]))) digit = true;
    if (digit)
      for (const char* t : kTokens) {
        std::string s = good;
        s.replace(b, e - b, t);
        if (!loads_sanely_or_errors(read, s, name + ": '" + good.substr(b, e - b) + "' at byte " + std::to_string(b) +
                                                   " -> '" + t + "'"))
          ++failures;
      }
    b = e;
  }
}

}  // namespace lumx_bad
