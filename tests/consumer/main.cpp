// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Reads an IES file through the installed lumx and prints its flux; exits non-zero on failure.
#include <lumx/io/photometry_io.h>
#include <lumx/photometry/metrics.h>
#include <lumx/version.h>

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  try {
    const lumx::Photometry p = lumx::read_photometry(argv[1]);
    const lumx::PhotometricSummary s = lumx::summarize(p);
    std::printf("lumx %s (%s): flux %.3f lm\n", lumx::kLibraryVersion, lumx::kAbiNamespace, s.flux_lm);
    return s.flux_lm > 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
}
