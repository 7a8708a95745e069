# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# The core component (lumx::lumx), included by lumxConfig.cmake. liblumx is static, so its private
# dependencies are linked by consumers too and must be found here.
find_dependency(glm CONFIG)
find_dependency(OpenEXR CONFIG)
find_dependency(OpenSSL COMPONENTS Crypto)
find_dependency(nlohmann_json CONFIG)
find_dependency(LibXml2)
find_dependency(PkgConfig)
pkg_check_modules(LIBZIP REQUIRED IMPORTED_TARGET libzip)  # as the build found it (CMakeLists.txt)
include("${CMAKE_CURRENT_LIST_DIR}/lumxCoreTargets.cmake")
if(TARGET lumx::lumx)
  set(lumx_core_FOUND_TARGETS TRUE)
else()
  set(lumx_core_FOUND_TARGETS FALSE)
endif()
