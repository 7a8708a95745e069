// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include <lumx/apl/far_field.h>
#include <lumx/model/far_field_model.h>

#include <cstdio>
#include <stdexcept>

LUMX_NAMESPACE_BEGIN

namespace {

constexpr int kMinResolution = 4, kMaxResolution = 1024;

std::shared_ptr<const AplSet> point_of(const Photometry& p, int map_resolution) {
  if (map_resolution < kMinResolution || map_resolution > kMaxResolution)
    throw std::invalid_argument("FarFieldModel: map resolution " + std::to_string(map_resolution) + " is not in [4, 1024]");
  return std::make_shared<const AplSet>(apl_set_from_photometry(p, map_resolution));
}

}  // namespace

FarFieldModel::FarFieldModel(Photometry photometry, int map_resolution)
    : photometry_(std::move(photometry)), point_(point_of(photometry_, map_resolution), 0) {}

std::string FarFieldModel::description() const {
  char text[96];
  std::snprintf(text, sizeof text, "far field, %zu horizontal x %zu vertical angles", photometry_.horizontal_deg.size(),
                photometry_.vertical_deg.size());
  return text;
}

LUMX_NAMESPACE_END
