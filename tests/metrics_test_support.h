// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Photometries with closed-form metrics (rotationally symmetric, intensity a function of gamma), and the
// reader of the UGR reference tables that ../shared holds (19 rows × 10 columns of numbers, "<10.0"
// where a program prints only a bound).
#pragma once

#include <lumx/photometry/photometry.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace lumx_test {

/// Type C, rotational symmetry, gamma 0..180 in `step_deg` steps, I(gamma) in cd; a rectangular luminous
/// area of `length_m` (X) × `width_m` (Y) when both are > 0.
inline lumx::Photometry rotational_photometry(const std::function<double(double)>& cd_of_gamma_deg, double step_deg = 1.0,
                                              double length_m = 0.6, double width_m = 0.6) {
  lumx::Photometry p;
  p.type = lumx::PhotometricType::C;
  p.symmetry = lumx::Symmetry::rotational;
  p.horizontal_deg = {0.0};
  for (double g = 0; g <= 180 + 1e-9; g += step_deg) p.vertical_deg.push_back(g);
  for (double g : p.vertical_deg) p.candela.push_back(cd_of_gamma_deg(g));
  p.absolute = true;
  p.opening.length_m = length_m;
  p.opening.width_m = width_m;
  p.source.file = "synthetic";
  p.source.format = "IES";
  return p;
}

/// A 19 × 10 UGR reference table; NaN where the file gives only a bound ("<10.0").
struct ReferenceTable {
  std::vector<std::vector<double>> rows;
  std::vector<std::vector<bool>> bound_only;
};

inline ReferenceTable read_reference_table(const std::filesystem::path& path) {
  ReferenceTable t;
  std::ifstream f(path);
  std::string line;
  while (std::getline(f, line)) {
    if (line.find_first_not_of(" \r\t") == std::string::npos) continue;
    std::vector<double> row;
    std::vector<bool> bound;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) {
      const bool b = cell.find('<') != std::string::npos;
      bound.push_back(b);
      row.push_back(b ? std::numeric_limits<double>::quiet_NaN() : std::stod(cell));
    }
    t.rows.push_back(row);
    t.bound_only.push_back(bound);
  }
  return t;
}

}  // namespace lumx_test
