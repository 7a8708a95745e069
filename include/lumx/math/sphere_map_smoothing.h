// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/math/sphere_map_smoothing.h — flux-exact pull-push smoothing of a sparse ray histogram on a sphere map.
//
// A map built from m rays over T texels has a relative noise of about 1/√(m/T) per texel; where few rays
// fell, a texel is mostly 0 or one ray's worth. Following the pull-push of seed 002 §5.2 (after Gortler et
// al.'s Lumigraph): the pull phase sums flux and ray counts up a pyramid of each hemisphere's square
// (R × R, R/2 × R/2, …, 1 × 1); the push phase walks down. A node with at least 4·min_rays rays (min_rays
// per child on average) splits its flux among its four children as the data does; a node with fewer
// splits it by a smooth shape: the `prior` map's flux in each child when one is given (an APL's parent in
// the coarser level: the same light, with more rays), otherwise the bilinear upsampling of the coarser
// pyramid level. Unlike 002, which replaces the values of sparse texels and so gains or loses light, each
// node here hands on exactly its flux, so every pyramid node, each hemisphere and the whole map keep their
// flux (up to rounding): the far field of a level does not change, only how a sparse map's light is placed.
//
// The decision is per parent, not per child: a child with no ray under a parent with many is evidence of
// darkness, not of sparsity (002 fills such texels from coarser levels and so leaks light across shadow
// borders, which it then has to detect; here a dense parent keeps its dark children dark). The kernel
// adapts to the data (as the adaptive kernels of seed 004): dense regions are unchanged, and the light of
// a sparse region is spread over the smallest pyramid node holding 4·min_rays of its rays. Why a prior:
// the bilinear shape blurs; when many APLs overlap (far away, or APLs that share one small emitter) their
// blurred maps sum to a blurred level. With the parent's map as the shape, where all children of a parent
// are sparse their smoothed maps sum back to the parent's map (overlapping APLs lose less; the bias
// that remains where siblings differ in density is measured in docs/apl_sets.md).
// Interpolation stays inside a hemisphere's square (clamped at its border, the equator); the two
// hemispheres split the map's flux by the data whenever it has a ray (a downlight's few rays must not
// light the ceiling), else by the prior or by area.
#pragma once

#include <lumx/version.h>

#include <cstdint>
#include <vector>

LUMX_NAMESPACE_BEGIN

/// Smooths `flux` (per texel, the 2R × R layout of SphereMap: index y·2R + x, left square z ≥ 0) given the
/// number of rays per texel `rays`; returns the smoothed flux per texel, whose sum equals the input's up
/// to rounding. A texel keeps its value when every pyramid node above it holds at least 4·min_rays rays
/// (a dense map is unchanged). R must be a power of two. min_rays ≤ 0 returns the input. `prior`, when
/// not null, holds 2R·R texels of flux (any scale) whose shape sparse nodes take.
std::vector<double> smooth_sparse_map(const std::vector<double>& flux, const std::vector<std::uint32_t>& rays,
                                      int R, double min_rays, const std::vector<double>* prior = nullptr);

LUMX_NAMESPACE_END
