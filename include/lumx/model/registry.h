// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/model/registry.h — light representations by name: how each is built from rays and how it is stored
// in a bundle (io/bundle_io.h), so that the bundle, the grading (model/grading.h), the room renderer and the
// CLI handle every registered representation without knowing its type.
//
// A new representation is one folder that implements LightModel and one registration:
//
//   static const lumx::ModelRegistration kMine{lumx::ModelType{"mine", "what it is", write, read, build}};
//
// A type's codec stores the model as a manifest section (a JSON object, passed as text so that no JSON
// library is part of this API) and any number of named payloads, each checksummed by the bundle. Reading
// gets the section back and reads only the payloads it asks for (partial loading: a representation with
// levels or resolutions reads the ones ModelLoadOptions allows).
#pragma once

#include <lumx/core/execution.h>
#include <lumx/model/light_model.h>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

class RaySource;

/// Where a codec writes its payloads while a bundle is written.
class ModelPayloadSink {
 public:
  virtual ~ModelPayloadSink() = default;
  /// Stores `bytes` as payload `name` (1–128 of [A-Za-z0-9._-], unique within the model). Throws
  /// lumx::Error for a bad or repeated name.
  virtual void add(const std::string& name, const std::string& bytes) = 0;
};

/// Where a codec reads its payloads while a bundle is read.
class ModelPayloadSource {
 public:
  virtual ~ModelPayloadSource() = default;
  /// The payload names the manifest lists for this model.
  virtual std::vector<std::string> names() const = 0;
  /// Size of payload `name` as the manifest states it (bytes); throws lumx::Error when there is none.
  virtual std::uint64_t size(const std::string& name) const = 0;
  /// The bytes of payload `name`, size- and SHA-256-checked; throws lumx::Error naming the file otherwise.
  virtual std::string read(const std::string& name) const = 0;
  /// The file or JSON pointer errors in this model's section are reported against.
  virtual const std::string& where() const = 0;
};

/// What a reader may leave out.
struct ModelLoadOptions {
  int max_resolution = 0;  ///< largest map or grid resolution to load (0: the full one)
};

/// A builder's settings: typed options travel as text by name, as the CLI passes them.
struct ModelBuildOptions {
  std::map<std::string, std::string> parameters;
  std::uint64_t seed = 1;
  ExecutionContext execution;
  /// parameters[key] as a number, or `fallback` when absent; throws std::invalid_argument when it does
  /// not parse completely.
  double number(const std::string& key, double fallback) const;
};

/// One registered representation.
struct ModelType {
  std::string name;         ///< unique: [a-z0-9-], e.g. "apl", "far-field"
  std::string description;  ///< one line
  /// Writes `model` (of this type) to a manifest section, returned as the text of one JSON object, and its
  /// payloads to `sink`. Empty: the representation is stored by the bundle itself (the APL levels).
  std::function<std::string(const LightModel& model, ModelPayloadSink& sink)> write;
  /// Reads a model from its section (JSON object text) and payloads. Throws lumx::Error naming
  /// payloads.where() and the field for anything malformed or absurd; allocations are bounded by what the
  /// payloads' stated sizes allow.
  std::function<std::unique_ptr<LightModel>(const std::string& section, const ModelPayloadSource& payloads,
                                            const ModelLoadOptions& options)>
      read;
  /// Builds a model from rays (streamed; deterministic for a seed whatever the thread count). Empty: not
  /// buildable from rays.
  std::function<std::unique_ptr<LightModel>(RaySource& rays, const ModelBuildOptions& options)> build;
};

/// Adds `type` to the registry. Throws std::invalid_argument for a bad or taken name. Thread-safe.
void register_model_type(ModelType type);
/// The registered type named `name`, or null. Thread-safe; the result stays valid for the process.
const ModelType* find_model_type(const std::string& name);
/// Every registered name, sorted.
std::vector<std::string> model_type_names();

/// Registers a type at static-initialisation time (one line per representation).
struct ModelRegistration {
  explicit ModelRegistration(ModelType type) { register_model_type(std::move(type)); }
};

/// Builds a model of registered type `type` from rays. Throws std::invalid_argument for an unknown type or
/// one without a builder.
std::unique_ptr<LightModel> build_model(const std::string& type, RaySource& rays, const ModelBuildOptions& options = {});

LUMX_NAMESPACE_END
