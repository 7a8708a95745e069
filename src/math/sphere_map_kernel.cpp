// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The SphereMapKernel constructor (math/sphere_map_kernel.h): each texel's neighbours within the
// truncation angle found on a uniform grid over the cube, their von Mises–Fisher weights normalised per
// source and stored in compressed rows of runs.
#include <lumx/math/sphere_map_kernel.h>

#include <lumx/math/sphere_map.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

LUMX_NAMESPACE_BEGIN

SphereMapKernel::SphereMapKernel(int resolution, double kappa) : resolution_(resolution), kappa_(kappa) {
  if (resolution < 1 || resolution > kMaxResolution)
    throw std::invalid_argument("SphereMapKernel: resolution " + std::to_string(resolution) + " outside [1, " +
                                std::to_string(kMaxResolution) + "]");
  if (!(kappa > 0) || !std::isfinite(kappa))
    throw std::invalid_argument("SphereMapKernel: kappa must be positive and finite");
  const int W = 2 * resolution, T = W * resolution;
  std::vector<glm::dvec3> centre(static_cast<std::size_t>(T));
  for (int y = 0; y < resolution; ++y)
    for (int x = 0; x < W; ++x)
      centre[std::size_t(y) * std::size_t(W) + std::size_t(x)] = glm::normalize(glm::dvec3(sphere_map::uv_to_direction(
          {(float(x) + 0.5f) / float(W), (float(y) + 0.5f) / float(resolution)})));
  const double cut = std::log(1e3) / kappa;  // 1 − cos of the truncation angle
  // The cap 1 − ω·ω' ≤ cut is cut/2 of the sphere: refuse a kernel that would hold more weights than
  // kMaxWeights rather than allocate them (a κ near 0 at R 128 would ask for 10⁹).
  if (double(T) * double(T) * std::min(1.0, cut / 2.0) > double(kMaxWeights))
    throw std::invalid_argument("SphereMapKernel: kappa " + std::to_string(kappa) + " at resolution " +
                                std::to_string(resolution) + " needs more than " + std::to_string(kMaxWeights) +
                                " weights; use a larger kappa or a lower resolution");
  // Neighbours by a uniform grid over the cube [−1, 1]³ whose cells are at least the truncation chord
  // √(2·cut) wide (|ω − ω'|² = 2(1 − ω·ω')), so every neighbour of a texel lies in the 27 cells around its
  // own. Each source's targets are then visited in increasing index, as a scan of all texels would, so
  // the weights and their sums do not depend on how the neighbours were found.
  const double chord = std::sqrt(2.0 * cut);
  const int cells = std::clamp(int(2.0 / chord), 1, 256);
  const auto cell_of = [&](double v) { return std::clamp(int((v + 1.0) * 0.5 * cells), 0, cells - 1); };
  std::vector<std::uint32_t> cell_start(std::size_t(cells) * cells * cells + 1, 0), in_cell(static_cast<std::size_t>(T));
  std::vector<std::uint32_t> cell_index(static_cast<std::size_t>(T));
  for (int t = 0; t < T; ++t) {
    const glm::dvec3& c = centre[std::size_t(t)];
    cell_index[std::size_t(t)] = std::uint32_t((cell_of(c.z) * cells + cell_of(c.y)) * cells + cell_of(c.x));
    ++cell_start[cell_index[std::size_t(t)] + 1];
  }
  for (std::size_t i = 1; i < cell_start.size(); ++i) cell_start[i] += cell_start[i - 1];
  {
    std::vector<std::uint32_t> fill(cell_start.begin(), cell_start.end() - 1);
    for (int t = 0; t < T; ++t) in_cell[fill[cell_index[std::size_t(t)]]++] = std::uint32_t(t);  // increasing t per cell
  }
  // Per source (increasing): its targets (increasing) as runs of consecutive texels (a cap crosses a
  // texel row in one run, or a few where it wraps an edge of the squares), its normalised weights in that
  // order and their normaliser. Runs let apply add a source to a row of targets in one contiguous loop
  // without an index load per weight, and take 8 bytes a run instead of 4 a weight. Only this order is stored: the
  // neighbour relation is symmetric, so a target's sources are the targets of its own row, and their
  // weights are recomputed from the centres and the normalisers when needed (local_linear_gain), to the
  // same bits.
  std::vector<std::pair<std::uint32_t, double>> row;
  offsets_.assign(std::size_t(T) + 1, 0);
  run_offsets_.assign(std::size_t(T) + 1, 0);
  normaliser_.assign(static_cast<std::size_t>(T), 0.0);
  for (int s = 0; s < T; ++s) {
    row.clear();
    const glm::dvec3& cs = centre[std::size_t(s)];
    const int cx = cell_of(cs.x), cy = cell_of(cs.y), cz = cell_of(cs.z);
    for (int z = std::max(0, cz - 1); z <= std::min(cells - 1, cz + 1); ++z)
      for (int y = std::max(0, cy - 1); y <= std::min(cells - 1, cy + 1); ++y)
        for (int x = std::max(0, cx - 1); x <= std::min(cells - 1, cx + 1); ++x) {
          const std::size_t cell = (std::size_t(z) * std::size_t(cells) + std::size_t(y)) * std::size_t(cells) + std::size_t(x);
          for (std::uint32_t i = cell_start[cell]; i < cell_start[cell + 1]; ++i) {
            const std::uint32_t t = in_cell[i];
            const double one_minus_cos = 1.0 - glm::dot(cs, centre[t]);
            if (one_minus_cos <= cut) row.push_back({t, std::exp(-kappa * one_minus_cos)});
          }
        }
    std::sort(row.begin(), row.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    double sum = 0;
    for (const auto& entry : row) sum += entry.second;
    for (const auto& [t, w] : row) {
      if (runs_.size() > run_offsets_[std::size_t(s)] && runs_.back().first + runs_.back().second == t)
        ++runs_.back().second;
      else
        runs_.push_back({t, 1});
      weights_.push_back(float(w / sum));
    }
    normaliser_[std::size_t(s)] = sum;
    offsets_[std::size_t(s) + 1] = std::uint32_t(weights_.size());
    run_offsets_[std::size_t(s) + 1] = std::uint32_t(runs_.size());
  }
  centres_ = std::move(centre);
}

LUMX_NAMESPACE_END
