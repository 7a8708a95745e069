// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include <lumx/model/registry.h>
#include <lumx/rays/rayset.h>

#include "model/builtin_models.h"

#include <algorithm>
#include <cstdlib>
#include <mutex>
#include <stdexcept>

LUMX_NAMESPACE_BEGIN

namespace {

struct Registry {
  std::mutex mutex;
  // Node-based, so that pointers handed out stay valid when types are added.
  std::map<std::string, std::unique_ptr<const ModelType>> types;
};

bool is_type_name(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  return std::all_of(name.begin(), name.end(),
                     [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-'; });
}

void add(Registry& r, ModelType type) {
  if (!is_type_name(type.name))
    throw std::invalid_argument("register_model_type: \"" + type.name + "\" is not a name of [a-z0-9-], 1-64 characters");
  if (r.types.count(type.name)) throw std::invalid_argument("register_model_type: \"" + type.name + "\" is taken");
  if (!type.read && type.write)
    throw std::invalid_argument("register_model_type: \"" + type.name + "\" writes a section it cannot read");
  std::string name = type.name;
  r.types.emplace(std::move(name), std::make_unique<const ModelType>(std::move(type)));
}

// The library's own types are registered on first use (not by static objects, which a static link of
// liblumx would drop), whatever the order of static initialisation of the types callers register.
Registry& registry() {
  static Registry* r = [] {
    auto* made = new Registry;
    add(*made, detail::apl_model_type());
    add(*made, detail::far_field_model_type());
    return made;
  }();
  return *r;
}

}  // namespace

double ModelBuildOptions::number(const std::string& key, double fallback) const {
  const auto it = parameters.find(key);
  if (it == parameters.end()) return fallback;
  const char* begin = it->second.c_str();
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (it->second.empty() || end != begin + it->second.size())
    throw std::invalid_argument("option " + key + "=\"" + it->second + "\" is not a number");
  return v;
}

void register_model_type(ModelType type) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  add(r, std::move(type));
}

const ModelType* find_model_type(const std::string& name) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  const auto it = r.types.find(name);
  return it == r.types.end() ? nullptr : it->second.get();
}

std::vector<std::string> model_type_names() {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  std::vector<std::string> names;
  for (const auto& [name, type] : r.types) names.push_back(name);
  return names;  // std::map: sorted
}

std::unique_ptr<LightModel> build_model(const std::string& type, RaySource& rays, const ModelBuildOptions& options) {
  const ModelType* t = find_model_type(type);
  if (!t) throw std::invalid_argument("build_model: no representation is registered as \"" + type + "\"");
  if (!t->build) throw std::invalid_argument("build_model: \"" + type + "\" cannot be built from rays");
  rays.rewind();
  std::unique_ptr<LightModel> m = t->build(rays, options);
  if (!m) throw std::invalid_argument("build_model: the builder of \"" + type + "\" returned nothing");
  return m;
}

LUMX_NAMESPACE_END
