// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The tracer's random streams (lumx/bake/random.h; hard-cases.md §6 items 40–41): particle i draws from
// Pcg32(seed, i) (the tracer also mixes i into the seed), and uses only its first few numbers. These tests look at exactly that use:
// the first draws of 2^20 consecutive streams, interleaved as the particles of one trace consume them, must
// be uniform in one and two dimensions, uncorrelated between neighbouring streams and between streams 2^k
// apart (where related LCG increments would show), with unbiased bits; and no stream repeats another. The
// same statistics reject a generator with a known flaw, so they can fail. (TestU01 and PractRand are not
// packaged for Debian 12; these are the classical tests, Knuth TAOCP vol. 2 §3.3.)
#include <lumx/bake/random.h>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <unordered_set>
#include <vector>

using lumx::bake::Pcg32;

namespace {

constexpr std::size_t kStreams = std::size_t(1) << 20;
constexpr int kDraws = 4;

/// z-score of a χ² statistic with `dof` degrees of freedom (normal approximation; dof ≥ 1000 here).
double chi2_z(double chi2, double dof) { return (chi2 - dof) / std::sqrt(2.0 * dof); }

/// The first kDraws numbers in [0, 1) of each of kStreams streams: draws[j][i] is stream i's j-th.
using Draws = std::array<std::vector<double>, kDraws>;
using StreamFactory = std::function<std::function<double()>(std::uint64_t stream)>;

Draws first_draws(const StreamFactory& make) {
  Draws d;
  for (auto& v : d) v.resize(kStreams);
  for (std::size_t i = 0; i < kStreams; ++i) {
    auto next = make(i);
    for (int j = 0; j < kDraws; ++j) d[j][i] = next();
  }
  return d;
}

/// The largest |z| over the statistics below; each is ~N(0, 1) for a good generator, so |z| < 5 (p < 6e-7
/// per statistic, for the ~70 statistics computed).
struct Verdict {
  double worst_z = 0;
  std::string worst;
  void add(double z, const std::string& what) {
    if (std::abs(z) > std::abs(worst_z)) worst_z = z, worst = what;
  }
};

Verdict judge(const Draws& d) {
  Verdict v;
  const double n = double(kStreams);
  // 1D: each draw in 4096 bins.
  for (int j = 0; j < kDraws; ++j) {
    std::vector<double> bins(4096, 0.0);
    for (double u : d[j]) bins[std::size_t(u * 4096)] += 1;
    double chi2 = 0;
    for (double b : bins) chi2 += (b - n / 4096) * (b - n / 4096) / (n / 4096);
    v.add(chi2_z(chi2, 4095), "1D draw " + std::to_string(j));
  }
  // 2D: (draw 0, draw 1) of one stream, and draw 0 of stream i with draw 0 of stream i + 1, in 64 × 64 bins.
  auto chi2_pairs = [&](const std::vector<double>& a, const std::vector<double>& b, std::size_t shift, const std::string& what) {
    std::vector<double> bins(4096, 0.0);
    const std::size_t m = kStreams - shift;
    for (std::size_t i = 0; i < m; ++i) bins[std::size_t(a[i] * 64) * 64 + std::size_t(b[i + shift] * 64)] += 1;
    double chi2 = 0;
    for (double c : bins) chi2 += (c - double(m) / 4096) * (c - double(m) / 4096) / (double(m) / 4096);
    v.add(chi2_z(chi2, 4095), what);
  };
  chi2_pairs(d[0], d[1], 0, "2D draws 0, 1 of a stream");
  chi2_pairs(d[2], d[3], 0, "2D draws 2, 3 of a stream");
  chi2_pairs(d[0], d[0], 1, "2D draw 0 of neighbouring streams");
  // Correlation of draw j of stream i with draw j of stream i + 2^k: r·√m ~ N(0, 1).
  for (int j = 0; j < 2; ++j)
    for (int k = 0; k <= 16; ++k) {
      const std::size_t shift = std::size_t(1) << k, m = kStreams - shift;
      double sum = 0;
      for (std::size_t i = 0; i < m; ++i) sum += (d[j][i] - 0.5) * (d[j][i + shift] - 0.5);
      v.add(sum / double(m) * 12.0 * std::sqrt(double(m)), "correlation of draw " + std::to_string(j) + " with stream +2^" + std::to_string(k));
    }
  // Bits: each of the top 24 bits of draw 0 is one half of the time, and so is its XOR with the same bit
  // of the neighbouring stream's draw 0 (binomial: z = (ones − m/2) / √(m/4)).
  for (int bit = 0; bit < 24; ++bit) {
    double ones = 0, differs = 0;
    for (std::size_t i = 0; i < kStreams; ++i) {
      const bool b = std::uint64_t(d[0][i] * 0x1.0p24) >> (23 - bit) & 1u;
      ones += b;
      if (i + 1 < kStreams) differs += b != bool(std::uint64_t(d[0][i + 1] * 0x1.0p24) >> (23 - bit) & 1u);
    }
    v.add((ones - n / 2) / std::sqrt(n / 4), "bit " + std::to_string(bit));
    v.add((differs - (n - 1) / 2) / std::sqrt((n - 1) / 4), "bit " + std::to_string(bit) + " xor neighbour");
  }
  return v;
}

}  // namespace

TEST(RandomStreams, UnitDoubleIsBelowOneAtTheLargestOutput) {
  EXPECT_EQ(Pcg32::unit_double(0, 0), 0.0);
  EXPECT_EQ(Pcg32::unit_double(0xFFFFFFFFu, 0xFFFFFFFFu), 1.0 - 0x1.0p-53);
  EXPECT_LT(Pcg32::unit_double(0xFFFFFFFFu, 0xFFFFFFFFu), 1.0);
  EXPECT_GT(1.0 - Pcg32::unit_double(0xFFFFFFFFu, 0xFFFFFFFFu), 0.0);  // 1 − u is never 0 either
  EXPECT_EQ(Pcg32::unit_double(0x80000000u, 0), 0.5);
  EXPECT_EQ(Pcg32::unit_double(0, 0x800u), 0x1.0p-53);  // the lowest bit kept
  EXPECT_EQ(Pcg32::unit_double(0, 0x7FFu), 0.0);        // the 11 bits dropped
}

TEST(RandomStreams, InterleavedFirstDrawsOfConsecutiveStreamsAreUniformAndIndependent) {
  for (const std::uint64_t seed : {std::uint64_t(1), std::uint64_t(0x5eed5eed5eedULL)}) {
    const Draws d = first_draws([seed](std::uint64_t stream) {
      auto rng = std::make_shared<Pcg32>(seed, stream);
      return [rng] { return rng->next_double(); };
    });
    const Verdict v = judge(d);
    EXPECT_LT(std::abs(v.worst_z), 5.0) << "seed " << seed << ": " << v.worst;
    std::printf("seed %llu: worst |z| %.2f (%s)\n", static_cast<unsigned long long>(seed), std::abs(v.worst_z), v.worst.c_str());
  }
}

// The statistics catch what they are meant to: streams that are one LCG started at consecutive seeds
// without mixing (a common mistake) are correlated between neighbours; and PCG32 as lumx first built it,
// the increment 2i + 1 taken from the index and the start from the seed alone, correlates streams 16 and
// 16384 apart (the finding that made Pcg32 hash both from the index; docs/robustness.md item 41).
TEST(RandomStreams, TheStatisticsRejectFlawedStreams) {
  const Draws lcg = first_draws([](std::uint64_t stream) {
    auto state = std::make_shared<std::uint64_t>(stream);
    return [state] {
      *state = *state * 6364136223846793005ULL + 1442695040888963407ULL;
      return double(*state >> 11) * 0x1.0p-53;
    };
  });
  const Verdict bad_lcg = judge(lcg);
  EXPECT_GT(std::abs(bad_lcg.worst_z), 5.0) << bad_lcg.worst;
  // PCG32 (XSH-RR) with increment 2i + 1 and a start from the seed only.
  struct UnmixedPcg {
    std::uint64_t state = 0, inc;
    UnmixedPcg(std::uint64_t seed, std::uint64_t stream) : inc(stream << 1u | 1u) {
      next();
      state += lumx::bake::mix64(seed);
      next();
    }
    std::uint32_t next() {
      const std::uint64_t old = state;
      state = old * Pcg32::kMultiplier + inc;
      return Pcg32::output(old);
    }
  };
  const Draws unmixed = first_draws([](std::uint64_t stream) {
    auto rng = std::make_shared<UnmixedPcg>(1, stream);
    return [rng] {
      const std::uint32_t hi = rng->next(), lo = rng->next();
      return Pcg32::unit_double(hi, lo);
    };
  });
  const Verdict bad_pcg = judge(unmixed);
  std::printf("unmixed LCG: worst |z| %.1f (%s); PCG32 with increment 2i + 1: worst |z| %.1f (%s)\n",
              std::abs(bad_lcg.worst_z), bad_lcg.worst.c_str(), std::abs(bad_pcg.worst_z), bad_pcg.worst.c_str());
  EXPECT_GT(std::abs(bad_pcg.worst_z), 20.0) << bad_pcg.worst;
  EXPECT_NE(bad_pcg.worst.find("stream +2^"), std::string::npos) << bad_pcg.worst;
}

// No stream repeats another: every window of two consecutive outputs (64 bits) among the first 2^14 of 256
// streams is distinct (2^22 windows: a chance collision has probability ~2^-21), and the first four outputs
// of 2^18 streams are distinct.
TEST(RandomStreams, StreamsNeverRepeatEachOther) {
  std::unordered_set<std::uint64_t> windows;
  windows.reserve(std::size_t(1) << 23);
  std::size_t repeats = 0;
  for (std::uint64_t s = 0; s < 256; ++s) {
    Pcg32 rng(7, s);
    std::uint64_t prev = rng.next_u32();
    for (int k = 1; k < (1 << 14); ++k) {
      const std::uint64_t cur = rng.next_u32();
      repeats += !windows.insert(prev << 32 | cur).second;
      prev = cur;
    }
  }
  EXPECT_EQ(repeats, 0u);
  std::unordered_set<std::uint64_t> heads;
  heads.reserve(std::size_t(1) << 19);
  for (std::uint64_t s = 0; s < (1u << 18); ++s) {
    Pcg32 rng(7, s);
    std::uint64_t h = 0;
    for (int k = 0; k < 4; ++k) h = lumx::bake::mix64(h ^ rng.next_u32());
    heads.insert(h);
  }
  EXPECT_EQ(heads.size(), std::size_t(1) << 18);
}
