// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// What every study program shares: its command line and the CSV it writes.
//
//   PROGRAM STUDY [--out FILE] [--seeds N] [--quick]     run one study
//   PROGRAM --list                                       the studies, one a line: name, then what it measures
//   PROGRAM --help
//
// A study writes one CSV, to stdout or to FILE: a header line, then one row per figure. Every study's
// columns are its own key columns (which set, resolution, kernel, …), then `quantity,d,value`: the
// quantity's name (a `_pct` suffix: percent), the relative distance d of the measurement sphere it is taken
// on (empty for a quantity that belongs to no sphere) and its value. studies/tables.py reads these files.
// Usage errors exit 2 with the usage on stderr, a failed study exits 1 with its error on stderr.
#pragma once

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace lumx_study {

/// A study's options. `seeds` is 0 where the command line gave none (each study has its default);
/// `quick` asks for the study's smaller variant (each study says what it leaves out).
struct StudyArgs {
  int seeds = 0;
  bool quick = false;
};

/// A cell: text as given (quoted when it holds a comma, a quote or a line break), numbers with up to 8
/// significant digits, integers exactly.
inline std::string cell(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (const char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}
inline std::string cell(const char* s) {
  return cell(std::string(s));
}
inline std::string cell(double v) {
  if (!std::isfinite(v)) return v != v ? "nan" : v > 0 ? "inf" : "-inf";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.8g", v);
  return buf;
}
template <class T, std::enable_if_t<std::is_integral_v<T> && !std::is_same_v<T, bool>, int> = 0>
std::string cell(T v) {
  return std::to_string(v);
}

/// A kernel's label in a CSV: "none" for κ ≤ 0, else kernel_mode_name's (lumx/math/sphere_map_kernel.h),
/// "plain" for its empty name.
inline std::string kernel_label(const char* mode_name, double kappa) {
  if (!(kappa > 0)) return "none";
  return *mode_name ? mode_name : "plain";
}

/// σ in degrees of a kernel of concentration κ (σ = 1/√κ), 0 for none.
inline double kernel_sigma_deg(double kappa) {
  return kappa > 0 ? 180.0 / 3.14159265358979323846 / std::sqrt(kappa) : 0.0;
}

/// The CSV of one study: key columns, then quantity, d, value. Each row is flushed as it is written.
class StudyCsv {
 public:
  StudyCsv(std::FILE* out, std::vector<std::string> keys) : out_(out), keys_(keys.size()) {
    std::string line;
    for (const std::string& k : keys) line += cell(k) + ",";
    std::fprintf(out_, "%squantity,d,value\n", line.c_str());
    std::fflush(out_);
  }
  /// A quantity taken on the measurement sphere at relative distance d.
  void put(const std::vector<std::string>& key, const std::string& quantity, double d, double value) {
    write(key, quantity, cell(d), value);
  }
  /// A quantity of no sphere (its d is left empty).
  void put(const std::vector<std::string>& key, const std::string& quantity, double value) {
    write(key, quantity, "", value);
  }

 private:
  void write(const std::vector<std::string>& key, const std::string& quantity, const std::string& d, double value) {
    if (key.size() != keys_)
      throw std::logic_error("StudyCsv: " + std::to_string(key.size()) + " keys for " + std::to_string(keys_) +
                             " columns");
    std::string line;
    for (const std::string& k : key) line += cell(k) + ",";
    std::fprintf(out_, "%s%s,%s,%s\n", line.c_str(), cell(quantity).c_str(), d.c_str(), cell(value).c_str());
    std::fflush(out_);
  }
  std::FILE* out_;
  std::size_t keys_;
};

/// One study of a program: its name on the command line, one line on what it measures (and on what
/// --seeds and --quick change), and its body, which writes its CSV to the stream it is given.
struct Study {
  const char* name;
  const char* summary;
  std::function<void(const StudyArgs&, std::FILE*)> run;
};

/// The program's main: parses the command line as the header comment describes and runs the study named.
inline int study_main(int argc, char** argv, const char* program_summary, const std::vector<Study>& studies) {
  const auto usage = [&](std::FILE* to) {
    std::fprintf(to, "%s\nUsage: %s STUDY [--out FILE] [--seeds N] [--quick]\n       %s --list\nStudies:\n",
                 program_summary, argv[0], argv[0]);
    for (const Study& s : studies) std::fprintf(to, "  %-16s %s\n", s.name, s.summary);
  };
  if (argc == 2 && (!std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h"))) {
    usage(stdout);
    return 0;
  }
  if (argc == 2 && !std::strcmp(argv[1], "--list")) {
    for (const Study& s : studies) std::printf("%s\t%s\n", s.name, s.summary);
    return 0;
  }
  if (argc < 2) {
    usage(stderr);
    return 2;
  }
  const Study* study = nullptr;
  for (const Study& s : studies)
    if (!std::strcmp(argv[1], s.name)) study = &s;
  StudyArgs args;
  std::string out_path;
  bool ok = study != nullptr;
  for (int i = 2; ok && i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") {
      args.quick = true;
    } else if ((a == "--out" || a == "--seeds") && i + 1 < argc) {
      const std::string v = argv[++i];
      if (a == "--out") {
        out_path = v;
      } else {
        char* end = nullptr;
        const long n = std::strtol(v.c_str(), &end, 10);
        ok = !v.empty() && *end == '\0' && n > 0 && n <= 100000;
        args.seeds = int(n);
      }
    } else {
      ok = false;
    }
  }
  if (!ok) {
    if (study)
      std::fprintf(stderr, "%s: bad arguments\n", argv[0]);
    else
      std::fprintf(stderr, "%s: no study %s\n", argv[0], argv[1]);
    usage(stderr);
    return 2;
  }
  std::FILE* out = stdout;
  if (!out_path.empty() && out_path != "-") {
    out = std::fopen(out_path.c_str(), "w");
    if (!out) {
      std::fprintf(stderr, "%s: cannot write %s: %s\n", argv[0], out_path.c_str(), std::strerror(errno));
      return 1;
    }
  }
  int status = 0;
  try {
    study->run(args, out);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s %s: %s\n", argv[0], study->name, e.what());
    status = 1;
  }
  if (out != stdout && std::fclose(out) != 0) status = 1;
  return status;
}

}  // namespace lumx_study
