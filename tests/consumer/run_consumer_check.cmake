# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# Installs the already-built lumx into WORK_DIR/prefix, then, against that installed tree only:
#  1. builds tests/consumer/core (COMPONENTS core) and runs it on SAMPLE;
#  2. checks that the core consumer's link line and its shared-library dependencies name no ray tracer,
#     task scheduler, glTF/mesh codec, plotting library or command-line parser (Embree, TBB, tinygltf,
#     Draco, cairo, CLI11), and that it does name liblumx (so the check looks at the real line) and
#     libxml2 (the static core's private TM-33 dependency, found through lumx-core.cmake);
#  3. builds tests/consumer/bake (COMPONENTS bake) and runs it;
#  4. asks for an unknown component and for each component this installation lacks: configuring must
#     fail with a message naming it;
#  5. installs the core component alone into a second prefix and compiles every header it holds on its own
#     against it (tests/consumer/headers), then does the same for every header of the whole installation
#     with every component it has.
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR}/scratch)
execute_process(COMMAND ${CMAKE_COMMAND} --install ${LUMX_BINARY_DIR} --prefix ${WORK_DIR}/prefix
                RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "install failed (${rc})")
endif()

# 1. The core consumer. Unix Makefiles, so the link command is in CMakeFiles/consumer.dir/link.txt.
# A sanitizer build of lumx needs the consumer linked with the same runtime (CONSUMER_FLAGS).
execute_process(COMMAND ${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR}/core -B ${WORK_DIR}/core -G "Unix Makefiles"
                        -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix "-DCMAKE_CXX_FLAGS=${CONSUMER_FLAGS}"
                        "-DCMAKE_EXE_LINKER_FLAGS=${CONSUMER_FLAGS}" RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring the core consumer failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/core RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "building the core consumer failed (${rc})")
endif()
execute_process(COMMAND ${WORK_DIR}/core/consumer ${SAMPLE} ${WORK_DIR}/scratch RESULT_VARIABLE rc
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "${out}${err}")
if(rc)
  message(FATAL_ERROR "the core consumer failed (${rc})")
endif()

# 2. What the core consumer links.
set(forbidden "embree|tbb|tinygltf|draco|cairo|cli11")
file(READ ${WORK_DIR}/core/CMakeFiles/consumer.dir/link.txt link_line)
string(TOLOWER "${link_line}" link_lower)
if(NOT link_lower MATCHES "liblumx")
  message(FATAL_ERROR "the core consumer's link line does not name liblumx:\n${link_line}")
endif()
# liblumx is static: its private dependencies (libxml2 for TM-33 among them) reach the consumer through
# find_dependency in lumx-core.cmake, which must name them.
if(NOT link_lower MATCHES "xml2")
  message(FATAL_ERROR "the core consumer's link line does not name libxml2 (lumx-core.cmake find_dependency):\n${link_line}")
endif()
if(link_lower MATCHES "(${forbidden})")
  message(FATAL_ERROR "the core consumer links '${CMAKE_MATCH_1}':\n${link_line}")
endif()
execute_process(COMMAND ldd ${WORK_DIR}/core/consumer OUTPUT_VARIABLE libs RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "ldd failed on the core consumer (${rc})")
endif()
string(TOLOWER "${libs}" libs_lower)
if(libs_lower MATCHES "(${forbidden})")
  message(FATAL_ERROR "the core consumer loads '${CMAKE_MATCH_1}' at run time:\n${libs}")
endif()
message(STATUS "core consumer: link line and shared libraries free of ${forbidden}")

file(READ ${WORK_DIR}/prefix/${INSTALL_LIBDIR}/cmake/lumx/lumxConfig.cmake config)
set(has_bake OFF)
if(config MATCHES "lumx_installed_components core bake")
  set(has_bake ON)
endif()

# 3. The bake consumer (COMPONENTS bake): traces a luminaire built in code.
if(has_bake)
execute_process(COMMAND ${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR}/bake -B ${WORK_DIR}/bake -G "Unix Makefiles"
                        -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix "-DCMAKE_CXX_FLAGS=${CONSUMER_FLAGS}"
                        "-DCMAKE_EXE_LINKER_FLAGS=${CONSUMER_FLAGS}" RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring the bake consumer failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/bake RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "building the bake consumer failed (${rc})")
endif()
execute_process(COMMAND ${WORK_DIR}/bake/consumer RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "${out}${err}")
if(rc)
  message(FATAL_ERROR "the bake consumer failed (${rc})")
endif()

endif()

# 4. Components the installation does not have.
set(absent nonesuch)
if(NOT has_bake)
  list(APPEND absent bake)
endif()
foreach(component IN LISTS absent)
  execute_process(COMMAND ${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR}/missing_component
                          -B ${WORK_DIR}/missing_${component} -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix
                          -DLUMX_COMPONENT=${component}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc)
    message(FATAL_ERROR "find_package(lumx COMPONENTS ${component}) succeeded on an installation without it")
  endif()
  if(NOT "${out}${err}" MATCHES "'${component}'")
    message(FATAL_ERROR "find_package(lumx COMPONENTS ${component}) failed without naming the component:\n${out}${err}")
  endif()
  message(STATUS "COMPONENTS ${component}: refused, naming it")
endforeach()

# 5. Every installed header on its own: of a core-only installation, then of the whole one.
execute_process(COMMAND ${CMAKE_COMMAND} --install ${LUMX_BINARY_DIR} --component core --prefix ${WORK_DIR}/core_prefix
                RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "installing the core component alone failed (${rc})")
endif()
set(header_checks "core_prefix|core")
if(has_bake)
  list(APPEND header_checks "prefix|core,bake")
endif()
foreach(check IN LISTS header_checks)
  string(REPLACE "|" ";" parts "${check}")
  list(GET parts 0 prefix)
  list(GET parts 1 components)
  string(REPLACE "," ";" components "${components}")
  string(MAKE_C_IDENTIFIER "${prefix}" tag)
  execute_process(COMMAND ${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR}/headers -B ${WORK_DIR}/headers_${tag} -G "Unix Makefiles"
                          -DCMAKE_PREFIX_PATH=${WORK_DIR}/${prefix} -DHEADER_ROOT=${WORK_DIR}/${prefix}/include
                          -DLUMX_PREFIX=${WORK_DIR}/${prefix} "-DLUMX_COMPONENTS=${components}"
                          "-DCMAKE_CXX_FLAGS=${CONSUMER_FLAGS}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(rc)
    message(FATAL_ERROR "configuring the header check of ${prefix} (COMPONENTS ${components}) failed:\n${out}${err}")
  endif()
  string(REGEX MATCH "installed headers compiled on their own: [0-9]+" count "${out}")
  execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/headers_${tag} -j 2
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(rc)
    message(FATAL_ERROR "an installed header of ${prefix} (COMPONENTS ${components}) does not compile on its own:\n${out}${err}")
  endif()
  message(STATUS "${prefix} (COMPONENTS ${components}): ${count}")
endforeach()
