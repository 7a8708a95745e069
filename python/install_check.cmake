# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# CTest python.install: installs the core and python components into a scratch prefix and imports the
# package from there, with nothing from the build tree on PYTHONPATH.
#   cmake -DBUILD_DIR=... -DPREFIX=... -DSITE=<folder under the prefix> -DPYTHON=... -DSAMPLE=x.ies -P install_check.cmake
file(REMOVE_RECURSE ${PREFIX})
foreach(component core python)
  execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --component ${component} --prefix ${PREFIX}
                  RESULT_VARIABLE rc OUTPUT_QUIET)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "installing component ${component} failed")
  endif()
endforeach()
execute_process(
  COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${PREFIX}/${SITE}
          ${PYTHON} -c "import lumx, sys; assert lumx.__file__.startswith(sys.argv[1]), lumx.__file__; print(lumx.read_photometry(sys.argv[2]).flux_lm)"
          ${PREFIX} ${SAMPLE}
  WORKING_DIRECTORY ${PREFIX}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "importing the installed package failed:\n${out}${err}")
endif()
message(STATUS "installed package imports; ${SAMPLE}: ${out} lm")
