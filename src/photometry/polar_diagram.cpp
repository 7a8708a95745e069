// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// make_polar_diagram (photometry/polar_diagram.h): the two planes sampled through IntensityTable, named
// by photometric type, and the rings sized for their maximum.
#include <lumx/photometry/polar_diagram.h>

#include <lumx/core/diagnostic.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/photometry/metrics.h>
#include <lumx/photometry/photometry.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

LUMX_NAMESPACE_BEGIN

PolarDiagram make_polar_diagram(const Photometry& p, const PolarDiagramOptions& options) {
  auto fail = [&](const char* field, const std::string& message) {
    Diagnostic d;
    d.file = p.source.file;
    d.field = field;
    d.message = message;
    throw Error(std::move(d));
  };
  if (!(options.step_deg > 0) || options.step_deg > 180)
    fail("step", "polar sampling step must be in (0, 180] degrees");

  PolarDiagram dg;
  dg.rated_lamp_flux_lm = p.rated_lamp_flux_lm();
  dg.relative = !options.force_cd && !p.absolute && dg.rated_lamp_flux_lm > 0;
  dg.unit = dg.relative ? "cd/klm" : "cd";
  dg.scale = dg.relative ? 1000.0 / dg.rated_lamp_flux_lm : 1.0;
  dg.title = polar_default_title(p);
  dg.file_name = detail::polar_base_name(p.source.file);

  for (std::size_t ih = 0; ih < p.num_horizontal(); ++ih)
    for (std::size_t iv = 0; iv < p.num_vertical() && ih * p.num_vertical() + iv < p.candela.size(); ++iv)
      if (p.at(ih, iv) > dg.max_cd) {
        dg.max_cd = p.at(ih, iv);
        dg.max_horizontal_deg = p.horizontal_deg[ih];
        dg.max_vertical_deg = p.vertical_deg[iv];
      }

  try {
    const IntensityTable t(p);
    dg.luminaire_flux_lm = t.flux_lm();
    dg.c0_c180.plane = SpreadPlane::c0_c180;
    dg.c90_c270.plane = SpreadPlane::c90_c270;
    dg.c0_c180.points = sample_polar_plane(t, SpreadPlane::c0_c180, dg.scale, options.step_deg);
    dg.c90_c270.points = sample_polar_plane(t, SpreadPlane::c90_c270, dg.scale, options.step_deg);
  } catch (const std::invalid_argument& e) {
    fail("intensity table", e.what());
  }

  // Plane names. Type C: C planes. Type B (polar axis Y): the X-Z plane is V = 0 (H runs across it), the
  // Y-Z plane is H = 0 (V runs across it). Type A (polar axis X): the other way round.
  switch (p.type) {
    case PhotometricType::C:
      dg.c0_c180.name = "C0 – C180";
      dg.c0_c180.positive_side = "C0";
      dg.c0_c180.negative_side = "C180";
      dg.c90_c270.name = "C90 – C270";
      dg.c90_c270.positive_side = "C90";
      dg.c90_c270.negative_side = "C270";
      break;
    case PhotometricType::B:
      dg.c0_c180.name = "V = 0° plane";
      dg.c0_c180.positive_side = "+H";
      dg.c0_c180.negative_side = "−H";
      dg.c90_c270.name = "H = 0° plane";
      dg.c90_c270.positive_side = "+V";
      dg.c90_c270.negative_side = "−V";
      break;
    case PhotometricType::A:
      dg.c0_c180.name = "H = 0° plane";
      dg.c0_c180.positive_side = "+V";
      dg.c0_c180.negative_side = "−V";
      dg.c90_c270.name = "V = 0° plane";
      dg.c90_c270.positive_side = "+H";
      dg.c90_c270.negative_side = "−H";
      break;
  }

  for (PolarCurve* c : {&dg.c0_c180, &dg.c90_c270})
    for (const PolarPoint& pt : c->points) c->max_value = std::max(c->max_value, pt.value);
  // 2 % headroom, so that a curve whose maximum is just below a nice value does not run along the outer
  // ring (an isotropic 1000 lm source peaks at 79.6 cd/klm: five rings of 20, not four).
  dg.rings = nice_ring_scale(kPolarRingHeadroom * std::max(dg.c0_c180.max_value, dg.c90_c270.max_value));
  return dg;
}

LUMX_NAMESPACE_END
