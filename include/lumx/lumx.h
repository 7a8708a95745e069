// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/lumx.h — the whole core component (lumx::lumx) in one include: every public header, by module.
// Embedders who want less include the module headers they use; each compiles on its own.
#pragma once

#include <lumx/version.h>

#include <lumx/core/diagnostic.h>
#include <lumx/core/execution.h>
#include <lumx/core/units.h>

#include <lumx/math/aabb.h>
#include <lumx/math/bounding_sphere.h>
#include <lumx/math/constants.h>
#include <lumx/math/direction_mask.h>
#include <lumx/math/line_fit.h>
#include <lumx/math/piecewise_constant_2d.h>
#include <lumx/math/pull_push.h>
#include <lumx/math/sphere_map.h>
#include <lumx/math/sphere_map_harmonics.h>
#include <lumx/math/sphere_map_kernel.h>
#include <lumx/math/sphere_map_sampler.h>
#include <lumx/math/sphere_map_smoothing.h>
#include <lumx/math/spherical_harmonics.h>

#include <lumx/photometry/far_field_grid.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/photometry/metrics.h>
#include <lumx/photometry/photometric_frame.h>
#include <lumx/photometry/photometry.h>
#include <lumx/photometry/polar_diagram.h>
#include <lumx/photometry/resample.h>
#include <lumx/photometry/symmetry.h>
#include <lumx/photometry/validate.h>

#include <lumx/rays/far_field.h>
#include <lumx/rays/holdout.h>
#include <lumx/rays/rayset.h>

#include <lumx/apl/apl_set.h>
#include <lumx/apl/builder.h>
#include <lumx/apl/clustering.h>
#include <lumx/apl/error.h>
#include <lumx/apl/map_fit.h>
#include <lumx/apl/evaluation.h>
#include <lumx/apl/far_field.h>
#include <lumx/apl/lod.h>
#include <lumx/apl/sampling.h>

#include <lumx/model/apl_model.h>
#include <lumx/model/far_field_model.h>
#include <lumx/model/grading.h>
#include <lumx/model/light_model.h>
#include <lumx/model/registry.h>

#include <lumx/volume/radiance_volume.h>

#include <lumx/render/adaptive_kernel_density.h>
#include <lumx/render/camera.h>
#include <lumx/render/image.h>
#include <lumx/render/room.h>
#include <lumx/render/spherical_kernel_density.h>

#include <lumx/io/atomic_file.h>
#include <lumx/io/bundle_io.h>
#include <lumx/io/photometry_io.h>
#include <lumx/io/tm33_io.h>
#include <lumx/io/gldf_io.h>
#include <lumx/io/rayset_io.h>
#include <lumx/render/image_io.h>
