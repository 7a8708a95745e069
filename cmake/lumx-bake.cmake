# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# The bake component (lumx::bake), included by lumxConfig.cmake after the core. liblumx_bake is static, so
# its private dependencies (Embree 3, TBB, Draco) are linked by consumers too and must be found here.
find_dependency(embree 3 CONFIG)
find_dependency(TBB CONFIG)
find_dependency(draco CONFIG)
include("${CMAKE_CURRENT_LIST_DIR}/lumxBakeTargets.cmake")
if(TARGET lumx::bake)
  set(lumx_bake_FOUND_TARGETS TRUE)
else()
  set(lumx_bake_FOUND_TARGETS FALSE)
endif()
