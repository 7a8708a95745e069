// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/bake/random.h — per-particle random streams: PCG32 (O'Neill 2014, "PCG: A Family of Simple Fast
// Space-Efficient Statistically Good Algorithms for Random Number Generation", §6.3 XSH-RR output on a
// 64-bit LCG). Particle i of a trace with seed s draws from an LCG stream selected by i (the increment)
// started at a state derived from s and i, so its numbers depend on (s, i) only: not on the thread, the
// chunk or the order in which particles are traced.
// LCG streams whose increments are related are themselves related (Vigna 2018, "The wrong way to use
// PCG streams"): with the increment 2i + 1 taken from the particle index directly, the first draws of
// particles i and i + 16 or i + 16384 correlate strongly (r·√n up to 63 over 2²⁰ particles). Both the
// increment and the start are therefore hashed from i (SplitMix64), which removes every such correlation
// that tests/test_random_streams.cpp measures.
#pragma once

#include <lumx/version.h>

#include <cstdint>

LUMX_NAMESPACE_BEGIN
namespace bake {

/// SplitMix64 finaliser (Steele, Lea & Flood 2014): a bijective 64-bit mix, here to decorrelate seeds.
inline std::uint64_t mix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

class Pcg32 {
 public:
  /// Stream `stream` (any 64-bit value; the LCG increment is 2·mix64(stream) + 1) started from a state
  /// that mixes `seed` and `stream`.
  Pcg32(std::uint64_t seed, std::uint64_t stream) : state_(0), inc_((mix64(stream) << 1u) | 1u) {
    next_u32();
    state_ += mix64(seed ^ mix64(stream ^ 0x6a09e667f3bcc909ULL));
    next_u32();
  }

  std::uint32_t next_u32() {
    const std::uint64_t old = state_;
    state_ = old * kMultiplier + inc_;
    return output(old);
  }

  /// The 64-bit LCG's multiplier (Knuth's MMIX constant, as PCG uses).
  static constexpr std::uint64_t kMultiplier = 6364136223846793005ULL;
  /// PCG's XSH-RR output permutation of a state (O'Neill 2014 §6.3.1): xorshift high, random rotation.
  static std::uint32_t output(std::uint64_t state) {
    const auto xorshifted = static_cast<std::uint32_t>(((state >> 18u) ^ state) >> 27u);
    const auto rot = static_cast<std::uint32_t>(state >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }

  /// Uniform in [0, 1): 53 random bits from two outputs, so that 1 − u is never 0 either.
  double next_double() {
    const std::uint32_t hi = next_u32(), lo = next_u32();
    return unit_double(hi, lo);
  }

  /// The top 53 of the 64 bits (hi, lo) as k · 2⁻⁵³, k < 2⁵³: exact, and at most 1 − 2⁻⁵³ (all ones).
  static double unit_double(std::uint32_t hi, std::uint32_t lo) {
    const std::uint64_t bits = (std::uint64_t(hi) << 32u) | lo;
    return static_cast<double>(bits >> 11u) * 0x1.0p-53;
  }

 private:
  std::uint64_t state_, inc_;
};

}  // namespace bake
LUMX_NAMESPACE_END
