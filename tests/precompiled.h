// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The test suite's precompiled header (tests/CMakeLists.txt, LUMX_PRECOMPILE_TESTS): the standard library,
// GoogleTest, nlohmann-json, GLM and the public lumx headers that two or more test files include. Parsing
// these took 8 of the 32 s one test file needs under the sanitizers; compiled once, every test file loads
// them instead. Each test file still includes what it uses, so the suite builds without this header too,
// and the library's headers are checked for self-containment by tests/header_units (no precompiled header).
#pragma once

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <lumx/apl/apl_set.h>
#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/apl/evaluation.h>
#include <lumx/apl/far_field.h>
#include <lumx/apl/lod.h>
#include <lumx/bake/bake.h>
#include <lumx/bake/gltf_reader.h>
#include <lumx/bake/gltf_writer.h>
#include <lumx/bake/luminaire_builder.h>
#include <lumx/bake/luminaire_check.h>
#include <lumx/bake/tracer.h>
#include <lumx/core/diagnostic.h>
#include <lumx/io/bundle_io.h>
#include <lumx/io/gldf_io.h>
#include <lumx/io/image_io.h>
#include <lumx/io/photometry_io.h>
#include <lumx/io/rayset_io.h>
#include <lumx/io/tm33_io.h>
#include <lumx/math/constants.h>
#include <lumx/math/sphere_map.h>
#include <lumx/math/sphere_map_kernel.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/photometry/metrics.h>
#include <lumx/photometry/photometric_frame.h>
#include <lumx/photometry/photometry.h>
#include <lumx/photometry/resample.h>
#include <lumx/photometry/symmetry.h>
#include <lumx/rays/far_field.h>
#include <lumx/rays/rayset.h>
#include <lumx/render/adaptive_kernel_density.h>
#include <lumx/render/spherical_kernel_density.h>
#include <lumx/volume/radiance_volume.h>
