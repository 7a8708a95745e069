// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// src/io/bundle/far_field_codec.cpp — the "far-field" representation's bundle codec (IES LM-63-2019 text,
// one payload) and builder (rays/far_field.h on a grid the ray count supports); registered in
// src/model/registry.cpp.
#include <lumx/core/diagnostic.h>
#include <lumx/io/photometry_io.h>
#include <lumx/model/far_field_model.h>
#include <lumx/model/registry.h>
#include <lumx/rays/far_field.h>

#include "model/builtin_models.h"

#include <nlohmann/json.hpp>

#include <stdexcept>

LUMX_NAMESPACE_BEGIN
namespace {

constexpr const char* kPayload = "far_field.ies";
constexpr std::uint64_t kMaxIesBytes = 64ull << 20;  // the IES reader's own file limit
constexpr int kMinResolution = 4, kMaxResolution = 1024;

}  // namespace

namespace detail {

ModelType far_field_model_type() {
  ModelType t;
  t.name = "far-field";
  t.description = "far-field photometry: one point at the photometric centre (IES LM-63 text)";
  t.write = [](const LightModel& model, ModelPayloadSink& sink) {
    const auto* m = dynamic_cast<const FarFieldModel*>(&model);
    if (!m) throw std::invalid_argument("far-field codec: the model is a \"" + model.type() + "\"");
    sink.add(kPayload, format_ies(m->photometry()));
    nlohmann::json section;
    section["payload"] = kPayload;
    section["map_resolution"] = m->point().level().map_resolution;
    return section.dump();
  };
  t.read = [](const std::string& text, const ModelPayloadSource& payloads, const ModelLoadOptions& options)
      -> std::unique_ptr<LightModel> {
    const std::string& where = payloads.where();
    const nlohmann::json section = nlohmann::json::parse(text, nullptr, false);
    if (!section.is_object()) throw_at_field(where, "section", "is not a JSON object");
    const auto r = section.find("map_resolution");
    if (r == section.end() || !r->is_number_integer())
      throw_at_field(where, "section/map_resolution", "must be an integer");
    const long long R = r->get<long long>();
    if (R < kMinResolution || R > kMaxResolution || (R & (R - 1)) != 0)
      throw_at_field(where, "section/map_resolution", std::to_string(R) + " is not a power of two in [4, 1024]");
    int resolution = int(R);
    while (options.max_resolution > 0 && resolution > options.max_resolution && resolution > kMinResolution) resolution /= 2;
    if (payloads.size(kPayload) > kMaxIesBytes)
      throw_at_field(where, std::string("payloads/") + kPayload, "larger than 64 MiB");
    const std::string ies = payloads.read(kPayload);
    return std::make_unique<FarFieldModel>(read_ies(ies, where + "!" + kPayload), resolution);
  };
  t.build = [](RaySource& rays, const ModelBuildOptions& o) -> std::unique_ptr<LightModel> {
    // Without steps given, the finest grid whose cells hold ≥ 100 rays on average (relative noise of an
    // isotropic source's cell ≤ 10 %): binned intensity is as noisy as the rays per cell allow.
    FarFieldGrid grid;
    const double rays_count = double(rays.info().ray_count);
    for (const auto& [c, g] : {std::pair{2.5, 1.0}, {5.0, 2.5}, {10.0, 5.0}, {15.0, 7.5}, {22.5, 10.0}, {30.0, 15.0}}) {
      grid.c_step_deg = c, grid.gamma_step_deg = g;
      if ((360 / c + 1) * (180 / g + 1) * 100 <= rays_count) break;
    }
    grid.c_step_deg = o.number("c-step", grid.c_step_deg);
    grid.gamma_step_deg = o.number("gamma-step", grid.gamma_step_deg);
    grid.luminous_efficacy_lm_per_w = o.number("efficacy", 0);
    return std::make_unique<FarFieldModel>(far_field_from_rays(rays, grid), int(o.number("map-resolution", 128)));
  };
  return t;
}

}  // namespace detail
LUMX_NAMESPACE_END
