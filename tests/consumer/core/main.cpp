// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// What a plugin does with the core component alone: read an IES file, write it as TM-33 XML and read that
// back (libxml2, a private dependency of the core), ship it as a one-APL bundle, open the bundle reading
// its manifest only, load the level at a reduced resolution, and query irradiance.
//
//   consumer FILE.ies SCRATCH_DIR      exit 0 when every check holds, 1 otherwise
//
// Checks: the TM-33 copy has the same candela table (exactly: shortest round-trip numbers), the bundle
// keeps the file's flux (0.5 %), and irradiance 3 m below the luminaire on a floor
// facing up equals the inverse-square law E = I(nadir) / d² from the file's own table within 2 %. The
// loaded maps are 32 × 32 per hemisphere (box-filtered), so at nadir the lookup averages the four texels
// that meet there, each a square of side a = sqrt(2π)/32 rad ≈ 4.5° with a corner at nadir, over which
// the mean of γ² is 2a²/3: the sample's cos^n lobe (n = 4…6 by C plane) reads low by about n·a²/3 ≈ 1 %.
#include <lumx/apl/evaluation.h>
#include <lumx/apl/far_field.h>
#include <lumx/io/bundle_io.h>
#include <lumx/io/photometry_io.h>
#include <lumx/io/tm33_io.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/photometry/metrics.h>
#include <lumx/version.h>

#include <cmath>
#include <cstdio>
#include <exception>
#include <string>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: consumer FILE.ies SCRATCH_DIR\n");
    return 2;
  }
  try {
    const lumx::Photometry p = lumx::read_photometry(argv[1]);
    const std::string tm33 = std::string(argv[2]) + "/consumer.xml";
    lumx::write_photometry(p, tm33);
    if (lumx::read_photometry(tm33).candela != p.candela) {
      std::fprintf(stderr, "the TM-33 copy %s has a different candela table\n", tm33.c_str());
      return 1;
    }
    const lumx::PhotometricSummary s = lumx::summarize(p);
    const lumx::IntensityTable table(p);
    const std::string bundle = std::string(argv[2]) + "/consumer.lumx";
    lumx::write_bundle(bundle, lumx::apl_set_from_photometry(p, 128));

    const lumx::BundleReader reader(bundle);
    lumx::AplSet set = reader.empty_set();
    set.levels.push_back(reader.load_level(0, 32));
    const double d = 3.0;
    const double e = lumx::irradiance(set, 0, glm::vec3(0, 0, -float(d)), glm::vec3(0, 0, 1)).irradiance.x;
    const double expected = table.intensity(glm::dvec3(0, 0, -1)) / (d * d);
    const double flux = set.levels[0].flux().x;
    std::printf("lumx %s (%s): flux %.3f lm (bundle %.3f lm); E(3 m below) %.4f lx, inverse-square %.4f lx\n",
                lumx::kLibraryVersion, lumx::kAbiNamespace, s.flux_lm, flux, e, expected);
    const bool ok = s.flux_lm > 0 && std::abs(flux - s.flux_lm) <= 0.005 * s.flux_lm &&
                    std::abs(e - expected) <= 0.02 * expected;
    return ok ? 0 : 1;
  } catch (const std::exception& ex) {
    std::fprintf(stderr, "%s\n", ex.what());
    return 1;
  }
}
