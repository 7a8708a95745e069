// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// libFuzzer target: any bytes as a glTF luminaire (.glb, or .gltf JSON with data URIs; Draco and
// quantized meshes included), under small limits, then what `lumx check` and `lumx bake` do next: the
// scene checked, its emitters' flux, and a few hundred particles traced. Only lumx::Error may come out.
//
//   bash scripts/fuzz.sh gltf 300
#include "fuzz_support.h"

#include <lumx/bake/gltf_reader.h>
#include <lumx/bake/luminaire_check.h>
#include <lumx/bake/tracer.h>

namespace {

struct Discard : lumx::bake::ParticleSink {
  void consume(const lumx::bake::ParticleChunk&) override {}
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static lumx_fuzz::ScratchFile glb(".glb"), gltf(".gltf");
  lumx::bake::GltfReadOptions o;
  o.warnings = [](const lumx::Diagnostic&) {};
  o.max_file_bytes = 1u << 20;
  o.max_buffer_bytes = 8u << 20;
  o.max_triangles = 100000;
  o.max_vertices = 300000;
  o.max_nodes_placed = 10000;
  o.max_parts = 1000;
  for (lumx_fuzz::ScratchFile* file : {&glb, &gltf}) {
    try {
      const lumx::bake::LuminaireScene scene = lumx::bake::read_gltf_luminaire(file->write(data, size), o);
      (void)lumx::bake::check_luminaire(scene);
      const lumx::bake::Tracer tracer(scene);
      lumx::bake::TraceOptions t;
      t.particles = 256;
      t.threads = 1;
      t.max_depth = 16;
      t.record_segments = true;
      Discard sink;
      (void)tracer.trace(t, sink);
    } catch (const lumx::Error&) {
    }
  }
  return 0;
}
