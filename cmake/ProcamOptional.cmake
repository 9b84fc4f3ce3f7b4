# Optional hardware libraries: each driver that needs one calls procam_optional()
# and is built only when the library is found. procam_print_summary() reports the
# outcome of every call at the end of configuration.
find_package(PkgConfig REQUIRED)

set_property(GLOBAL PROPERTY PROCAM_SUMMARY "")

# procam_optional(<var> <what> <pkg-config module>...)
# Sets <var>_FOUND and an imported target PkgConfig::<var> when all modules exist.
function(procam_optional var what)
  pkg_check_modules(${var} QUIET IMPORTED_TARGET GLOBAL ${ARGN})
  string(REPLACE ";" ", " modules "${ARGN}")
  if(${var}_FOUND)
    set(line "  [built]   ${what} (pkg-config: ${modules})")
  else()
    set(line "  [skipped] ${what}: pkg-config module(s) not found: ${modules}")
  endif()
  set_property(GLOBAL APPEND PROPERTY PROCAM_SUMMARY "${line}")
  set(${var}_FOUND ${${var}_FOUND} PARENT_SCOPE)
endfunction()

# procam_note(<line>): add a free-form line to the summary.
function(procam_note line)
  set_property(GLOBAL APPEND PROPERTY PROCAM_SUMMARY "  ${line}")
endfunction()

function(procam_print_summary)
  get_property(lines GLOBAL PROPERTY PROCAM_SUMMARY)
  message(STATUS "procamd configuration summary:")
  foreach(line IN LISTS lines)
    message(STATUS "${line}")
  endforeach()
  if(PROCAM_ASAN)
    message(STATUS "  sanitizers: address, undefined")
  endif()
endfunction()
