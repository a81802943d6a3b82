# Soak runs (label soak): long renders and chi-square runs that draw the rare sample values short
# tests never reach (tests/soak/soak.py says what each does). About 7 minutes on 2 cores, so they
# are registered only with -DFACET_SOAK=ON and are not part of CI's suite:
#   cmake -S . -B build -DFACET_SOAK=ON && cmake --build build -j2 && ctest --test-dir build -L soak
# Together: 5 renders of 128x128 pixels x 64 spp x 256 emitter samples (1.6e9 emitter samples:
# orthogonal rounds the spp up; each sampler once), one light-tracing render, and `facet chi2` with 1e8 samples on every emitter
# configuration of tests/chi2/configs.txt.
option(FACET_SOAK "Register the soak tests (label soak; long)" OFF)
if(NOT FACET_SOAK)
    message(STATUS "soak: not registered (-DFACET_SOAK=ON registers them)")
    return()
endif()
if(NOT TARGET facet_cli)
    return()
endif()
find_package(Python3 REQUIRED COMPONENTS Interpreter)
set(_soak ${CMAKE_CURRENT_SOURCE_DIR}/soak/soak.py)
set(_work ${CMAKE_BINARY_DIR}/tests/soak)
foreach(_sampler independent stratified multijitter orthogonal ldsampler)
    add_test(NAME soak.render.${_sampler}
             COMMAND ${Python3_EXECUTABLE} ${_soak} render $<TARGET_FILE:facet_cli> ${_work}
                     ${_sampler} 256)
endforeach()
add_test(NAME soak.render.ptracer
         COMMAND ${Python3_EXECUTABLE} ${_soak} ptracer $<TARGET_FILE:facet_cli> ${_work})
set(_configs ${CMAKE_CURRENT_SOURCE_DIR}/chi2/configs.txt)
file(STRINGS ${_configs} _lines)
set(_emitter_lines "")
set(_number 0)
foreach(_line IN LISTS _lines)
    math(EXPR _number "${_number} + 1")
    string(STRIP "${_line}" _line)
    if(_line MATCHES "^emitter ")
        list(APPEND _emitter_lines ${_number})
    endif()
endforeach()
list(LENGTH _emitter_lines _count)
# In the work folder: the pictures of a rejection (chi2-failures/) go there, not into the sources.
file(MAKE_DIRECTORY ${_work})
foreach(_number IN LISTS _emitter_lines) # Sidak-corrected over the soak's chi2 runs
    add_test(NAME soak.chi2.line${_number}
             COMMAND ${Python3_EXECUTABLE} ${_soak} chi2 $<TARGET_FILE:facet_cli> ${_configs}
                     ${_number} 100000000 ${_count}
             WORKING_DIRECTORY ${_work})
endforeach()
get_property(_soak_tests DIRECTORY PROPERTY TESTS)
list(FILTER _soak_tests INCLUDE REGEX "^soak\\.")
set_tests_properties(${_soak_tests} PROPERTIES LABELS soak TIMEOUT 1800 RUN_SERIAL TRUE)
message(STATUS "soak: 6 renders and ${_count} chi2 runs of 1e8 samples registered (label soak)")
