# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# lumx_header_units(OUT ROOT DIR [SKIP regex]): one translation unit per public header under ROOT/lumx
# (detail/ parts and headers matching SKIP left out), each including its header twice (the second checks
# the include guard), written to DIR; their paths in OUT. Used by the tests' header check and by
# tests/consumer/headers, which compiles an installation's headers the same way.
function(lumx_header_units out root dir)
  cmake_parse_arguments(PARSE_ARGV 3 arg "" "SKIP" "")
  file(GLOB_RECURSE headers CONFIGURE_DEPENDS RELATIVE ${root} ${root}/lumx/*.h)
  set(units)
  foreach(header IN LISTS headers)
    if(header MATCHES "/detail/" OR (arg_SKIP AND header MATCHES "${arg_SKIP}"))
      continue()
    endif()
    string(MAKE_C_IDENTIFIER "${header}" unit)
    set(unit_file ${dir}/${unit}.cpp)
    file(CONFIGURE OUTPUT ${unit_file} CONTENT "#include <${header}>\n#include <${header}>  // include guard\n")
    list(APPEND units ${unit_file})
  endforeach()
  set(${out} ${units} PARENT_SCOPE)
endfunction()
