// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The lumx subcommands applied to glTF 2.0 luminaires (.gltf, .glb): info (parts, the scattering model each
// material maps to, emitters and their flux, bounding box) and check (the reader's warnings and
// lumx::bake::check_luminaire's findings).
#include "commands.h"

#include "cli_support.h"

#include <lumx/bake/gltf_reader.h>
#include <lumx/bake/luminaire_check.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>

namespace lumx_cli {

using nlohmann::json;
namespace bake = lumx::bake;

bool is_luminaire_path(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".gltf" || ext == ".glb";
}

namespace {

std::string format(const char* fmt, double a, double b = 0.0) {
  char buf[128];
  std::snprintf(buf, sizeof buf, fmt, a, b);
  return buf;
}

/// The scattering model a material maps to (lumx/bake/bsdf.h), in a few words.
std::string material_model(const bake::Material& m) {
  const double alpha = m.roughness * m.roughness;
  std::string s;
  if (m.emissive_any())
    s = "emitter " + format("%.6g cd/m²", bake::luminance(m.emitted_luminance())) +
        (m.double_sided ? " two-sided; " : " one-sided; ");
  if (m.transmission > 0.0) {
    s += m.volume ? "rough dielectric volume" : "thin rough dielectric";
    s += format(" η=%.6g α=%.4g", m.ior, alpha);
    if (m.transmission < 1.0) s += format(" (transmission %.3g)", m.transmission);
    if (m.volume && std::isfinite(m.attenuation_distance_m)) s += format(", absorbing over %.4g m", m.attenuation_distance_m);
  } else if (m.diffuse_transmission > 0.0) {
    s += format("diffuse transmitter (%.3g) over Lambertian ρ=%.3g", m.diffuse_transmission, bake::luminance(m.base_color));
  } else if (m.metallic >= 1.0) {
    s += format("rough conductor α=%.4g", alpha);
  } else if (m.metallic <= 0.0) {
    s += format("Lambertian ρ=%.3g + dielectric specular η=%.6g", bake::luminance(m.base_color), m.ior) +
         format(" α=%.4g", alpha);
  } else {
    s += format("conductor/dielectric blend (metallic %.3g) α=%.4g", m.metallic, alpha);
  }
  if (m.volume && m.transmission <= 0.0) s += " (volume without transmission)";
  return s;
}

double part_area(const bake::LuminaireScene& s, const bake::Part& p) {
  double a = 0.0;
  for (std::uint32_t t = 0; t < p.triangle_count; ++t) a += bake::triangle_area(s, p.first_triangle + t);
  return a;
}

struct Box {
  glm::dvec3 lo{std::numeric_limits<double>::infinity()}, hi{-std::numeric_limits<double>::infinity()};
  bool empty() const { return !(lo.x <= hi.x); }
};

Box bounds(const bake::LuminaireScene& s) {
  Box b;
  for (const auto& p : s.positions) {
    b.lo = glm::min(b.lo, glm::dvec3(p));
    b.hi = glm::max(b.hi, glm::dvec3(p));
  }
  for (const auto& e : s.emitters)
    if (e.kind != bake::EmitterKind::surface) {
      const glm::dvec3 p(e.to_world[3]);
      b.lo = glm::min(b.lo, p);
      b.hi = glm::max(b.hi, p);
    }
  return b;
}

/// Flux of an emitter, or NaN with `error` set when it cannot be computed (a ray file that fails to read).
double flux_of(const bake::LuminaireScene& s, const bake::Emitter& e, std::string& error) {
  try {
    return bake::emitter_flux_lm(s, e);
  } catch (const lumx::Error& err) {
    error = err.what();
    return std::numeric_limits<double>::quiet_NaN();
  }
}

json nullable(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

}  // namespace

int run_luminaire_info(const InfoArgs& a) {
  return guarded(a.file, [&] {
    const bake::LuminaireScene s = bake::read_gltf_luminaire(a.file);
    const Box box = bounds(s);
    double total = 0.0;
    if (a.json) {
      json parts = json::array();
      for (const auto& p : s.parts) {
        const auto& m = s.materials[p.material];
        parts.push_back({{"name", p.name},
                         {"source", p.source},
                         {"node", p.node},
                         {"triangles", p.triangle_count},
                         {"area_m2", part_area(s, p)},
                         {"closed", p.closed},
                         {"material", p.material},
                         {"material_name", m.name},
                         {"model", material_model(m)}});
      }
      json emitters = json::array();
      for (const auto& e : s.emitters) {
        std::string error;
        const double f = flux_of(s, e, error);
        if (std::isfinite(f)) total += f;
        json j = {{"kind", bake::to_string(e.kind)}, {"name", e.name}, {"source", e.source}, {"flux_lm", nullable(f)}};
        if (e.kind == bake::EmitterKind::surface) j["part"] = e.part;
        if (e.kind != bake::EmitterKind::surface)
          j["position_m"] = {e.to_world[3][0], e.to_world[3][1], e.to_world[3][2]};
        if (e.kind == bake::EmitterKind::rayset) j["rayset"] = e.rayset_path;
        if (!error.empty()) j["error"] = error;
        emitters.push_back(j);
      }
      json j = {{"file", a.file},
                {"triangles", s.triangle_count()},
                {"vertices", s.positions.size()},
                {"normals", !s.normals.empty()},
                {"bounding_box_m", box.empty() ? json(nullptr)
                                               : json{{"min", {box.lo.x, box.lo.y, box.lo.z}},
                                                      {"max", {box.hi.x, box.hi.y, box.hi.z}}}},
                {"parts", parts},
                {"emitters", emitters},
                {"total_flux_lm", total},
                {"warnings", json::array()}};
      for (const auto& w : s.warnings) j["warnings"].push_back(diag_json(w));
      std::cout << j.dump(2, ' ', false, json::error_handler_t::replace) << "\n";
      return 0;
    }
    for (const auto& w : s.warnings) print_diag(w);
    std::printf("file:          %s\n", a.file.c_str());
    std::printf("geometry:      %zu triangles in %zu parts, %zu vertices, %s\n", s.triangle_count(), s.parts.size(),
                s.positions.size(), s.normals.empty() ? "no normals (flat shading)" : "vertex normals");
    if (!box.empty())
      std::printf("bounding box:  x %.6g..%.6g, y %.6g..%.6g, z %.6g..%.6g m (glTF axes, +y up)\n", box.lo.x, box.hi.x,
                  box.lo.y, box.hi.y, box.lo.z, box.hi.z);
    std::printf("parts:\n");
    for (const auto& p : s.parts) {
      const auto& m = s.materials[p.material];
      std::printf("  %-16s %7u triangles, %.6g m², %-6s  material '%s': %s\n", p.name.c_str(), p.triangle_count,
                  part_area(s, p), p.closed ? "closed" : "open", m.name.c_str(), material_model(m).c_str());
    }
    std::printf("emitters:\n");
    if (s.emitters.empty()) std::printf("  none\n");
    for (const auto& e : s.emitters) {
      std::string error;
      const double f = flux_of(s, e, error);
      if (std::isfinite(f)) total += f;
      std::printf("  %-8s '%s' (%s): %s\n", bake::to_string(e.kind), e.name.c_str(), e.source.c_str(),
                  error.empty() ? format("%.6g lm", f).c_str() : error.c_str());
    }
    std::printf("total flux:    %.6g lm (emitted, before any loss in the luminaire)\n", total);
    return 0;
  });
}

std::vector<lumx::Diagnostic> check_luminaire_file(const std::string& path) {
  std::vector<lumx::Diagnostic> findings;
  try {
    const bake::LuminaireScene s = bake::read_gltf_luminaire(path);
    findings = s.warnings;
    for (auto& d : bake::check_luminaire(s)) findings.push_back(d);
  } catch (const lumx::Error& e) {
    findings.push_back(e.diagnostic());
  }
  return findings;
}

}  // namespace lumx_cli
