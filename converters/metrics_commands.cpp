// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The metrics part of `lumx info` and the metric diagrams of `lumx plot` (see metrics_commands.h).
#include "metrics_commands.h"

#include "metric_plots.h"

#include <lumx/core/diagnostic.h>
#include <lumx/photometry/bug_rating.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/photometry/luminance_table.h>
#include <lumx/photometry/spacing_criterion.h>
#include <lumx/photometry/ugr.h>
#include <lumx/photometry/zonal_flux.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>

namespace lumx_cli {
namespace {

using nlohmann::json;

json opt(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

// Runs `f` into j[name]; a model error leaves null there and the reason in j[name + "_error"].
void guarded_metric(json& j, const std::string& name, const std::function<json()>& f) {
  try {
    j[name] = f();
  } catch (const lumx::Error& e) {
    j[name] = nullptr;
    j[name + "_error"] = e.what();
  } catch (const std::invalid_argument& e) {
    j[name] = nullptr;
    j[name + "_error"] = e.what();
  }
}

json zone_json(const lumx::Zone& z) {
  return {{"gamma_deg", {z.gamma_min_deg, z.gamma_max_deg}},
          {"lm", z.lm},
          {"percent_lamp", opt(z.percent_lamp)},
          {"percent_luminaire", z.percent_luminaire}};
}

json ugr_json(const lumx::UgrTable& t) {
  json rooms = json::array(), refl = json::array(), cross = json::array(), end = json::array();
  for (const auto& r : t.options.rooms) rooms.push_back({r.x_h, r.y_h});
  for (const auto& r : t.options.reflectances) refl.push_back({r.ceiling, r.walls, r.floor});
  for (std::size_t i = 0; i < t.options.rooms.size(); ++i) {
    json c = json::array(), e = json::array();
    for (std::size_t k = 0; k < t.options.reflectances.size(); ++k) {
      c.push_back(t.at(i, k, lumx::UgrView::crosswise));
      e.push_back(t.at(i, k, lumx::UgrView::endwise));
    }
    cross.push_back(c);
    end.push_back(e);
  }
  return {{"method", "CIE 117:1995 / CIE 190:2010 tabular method"},
          {"spacing_to_height", t.options.spacing_to_height},
          {"height_m", t.options.height_m},
          {"luminaire_flux_lm", t.luminaire_flux_lm},
          {"rooms_xy_h", rooms},
          {"reflectances_cwf", refl},
          {"crosswise", cross},
          {"endwise", end}};
}

// The 4H x 8H room at 0.7/0.5/0.2: the pair catalogues quote.
bool reference_ugr(const lumx::UgrTable& t, double& cross, double& end) {
  for (std::size_t i = 0; i < t.options.rooms.size(); ++i)
    if (t.options.rooms[i].x_h == 4 && t.options.rooms[i].y_h == 8) {
      cross = t.at(i, 0, lumx::UgrView::crosswise);
      end = t.at(i, 0, lumx::UgrView::endwise);
      return true;
    }
  return false;
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

}  // namespace

json metrics_json(const lumx::Photometry& p) {
  json j = json::object();
  guarded_metric(j, "zonal_lumens", [&] {
    const lumx::ZonalLumenSummary z = lumx::zonal_lumen_summary(p);
    json s = json::array(), ten = json::array();
    for (const auto& zz : z.summary) s.push_back(zone_json(zz));
    for (const auto& zz : z.ten_degree) ten.push_back(zone_json(zz));
    return json{{"luminaire_lm", z.luminaire_lm}, {"lamp_lm", opt(z.lamp_lm)}, {"summary", s}, {"ten_degree", ten}};
  });
  guarded_metric(j, "cie_flux_code", [&] {
    const lumx::CieFluxCode c = lumx::cie_flux_code(p);
    return json{{"code", c.str()}, {"n1", c.n1}, {"n2", c.n2}, {"n3", c.n3}, {"n4", c.n4}, {"n5", opt(c.n5)}};
  });
  guarded_metric(j, "bug_rating", [&] {
    const lumx::BugRating b = lumx::bug_rating(p);
    const auto& z = b.zones;
    return json{{"rating", b.str()},
                {"b", b.b},
                {"u", b.u},
                {"g", b.g},
                {"forward_c_deg", lumx::BugOptions{}.forward_c_deg},
                {"quadrilateral_symmetric", b.quadrilateral_symmetric},
                {"zones_lm",
                 {{"FL", z.fl}, {"FM", z.fm}, {"FH", z.fh}, {"FVH", z.fvh}, {"BL", z.bl}, {"BM", z.bm}, {"BH", z.bh},
                  {"BVH", z.bvh}, {"UL", z.ul}, {"UH", z.uh}}}};
  });
  guarded_metric(j, "spacing_criterion", [&] {
    const lumx::SpacingCriterion s = lumx::spacing_criteria(lumx::IntensityTable(p));
    return json{{"c0_c180", opt(s.c0_c180)}, {"c90_c270", opt(s.c90_c270)}, {"diagonal", opt(s.diagonal)}};
  });
  guarded_metric(j, "luminance_cd_m2", [&] {
    const lumx::LuminanceTable l = lumx::luminance_table(p);
    json rows = json::array();
    for (std::size_t ic = 0; ic < l.c_deg.size(); ++ic) {
      json r = json::array();
      for (std::size_t ig = 0; ig < l.gamma_deg.size(); ++ig) r.push_back(l.at(ic, ig));
      rows.push_back(r);
    }
    return json{{"c_deg", l.c_deg}, {"gamma_deg", l.gamma_deg}, {"values", rows}, {"max", l.max_cd_m2}};
  });
  guarded_metric(j, "ugr", [&] { return ugr_json(lumx::ugr_table(p)); });
  return j;
}

void print_metrics_summary(const lumx::Photometry& p) {
  auto report = [](const char* label, const std::function<std::string()>& f) {
    std::string s;
    try {
      s = f();
    } catch (const lumx::Error& e) {
      s = std::string("n/a (") + e.diagnostic().field + ": " + e.diagnostic().message + ")";
    } catch (const std::invalid_argument& e) {
      s = std::string("n/a (") + e.what() + ")";
    }
    std::printf("%-15s%s\n", label, s.c_str());
  };
  report("zonal lumens:", [&] {
    const lumx::ZonalLumenSummary z = lumx::zonal_lumen_summary(p);
    std::string s;
    for (const auto& zz : z.summary) {
      if (!s.empty()) s += ", ";
      s += fmt("%.0f", zz.gamma_min_deg) + "-" + fmt("%.0f", zz.gamma_max_deg) + " " + fmt("%.1f %%", zz.percent_luminaire);
    }
    return s + " of the luminaire flux";
  });
  report("CIE flux code:", [&] { return lumx::cie_flux_code(p).str(); });
  report("BUG rating:", [&] { return lumx::bug_rating(p).str() + " (front: the half around C90)"; });
  report("spacing (SC):", [&] {
    const lumx::SpacingCriterion s = lumx::spacing_criteria(lumx::IntensityTable(p));
    auto v = [](const std::optional<double>& x) { return x ? fmt("%.2f", *x) : std::string("none"); };
    return v(s.c0_c180) + " (C0-C180), " + v(s.c90_c270) + " (C90-C270), " + v(s.diagonal) + " (diagonal)";
  });
  report("luminance:", [&] {
    return "max " + fmt("%.0f", lumx::luminance_table(p).max_cd_m2) + " cd/m2 at gamma 45-85 deg";
  });
  report("UGR 4Hx8H:", [&] {
    double c = 0, e = 0;
    if (!reference_ugr(lumx::ugr_table(p), c, e)) return std::string("n/a");
    return fmt("%.1f", c) + " crosswise, " + fmt("%.1f", e) + " endwise (0.7/0.5/0.2, S = 0.25 H)";
  });
}

int run_metric_plot(const PlotArgs& a, const lumx::Photometry& p) {
  lumx::MetricPlotOptions o;
  o.title = a.title;
  o.size_px = a.size_px;
  o.mounting_height_m = a.mounting_height_m;
  o.tilt_deg = a.tilt_deg;
  o.spacing_to_height = a.spacing_to_height;
  if (!a.distances_m.empty()) o.distances_m = a.distances_m;
  lumx::PlotSummary s;
  if (a.kind == "isolux")
    s = lumx::write_isolux_plot(p, a.out, o);
  else if (a.kind == "isocandela")
    s = lumx::write_isocandela_plot(p, a.out, o);
  else if (a.kind == "cone")
    s = lumx::write_cone_plot(p, a.out, o);
  else if (a.kind == "ugr")
    s = lumx::write_ugr_plot(p, a.out, o);
  else
    lumx::throw_at_field(a.out, "kind", "unknown diagram '" + a.kind + "' (polar, isolux, isocandela, cone, ugr)");
  std::string labels;
  for (const auto& l : s.labels) labels += (labels.empty() ? "" : " | ") + l;
  std::printf("%s\n%s labels: %s\n", a.out.c_str(), s.kind.c_str(), labels.c_str());
  return 0;
}

}  // namespace lumx_cli
