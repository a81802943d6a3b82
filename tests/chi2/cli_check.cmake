# Run with cmake -P: checks what `facet chi2` does with a correct and a deliberately wrong
# sampler (tests/chi2_plugins/chi2_lambert_bug.cpp): exit codes, verdict lines, heat maps.
# Inputs: -DFACET=<facet binary> -DPLUGIN_DIR=<folder with chi2_lambert_bug.so> -DWORK=<scratch>

foreach(v FACET PLUGIN_DIR WORK)
    if(NOT DEFINED ${v})
        message(FATAL_ERROR "cli_check.cmake: ${v} is not set")
    endif()
endforeach()
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

function(run_chi2 expect_code expect_text)
    execute_process(COMMAND ${FACET} chi2 bsdf chi2_lambert_bug -a ${PLUGIN_DIR} --samples 200000
                            --res 16 ${ARGN}
                    WORKING_DIRECTORY ${WORK} RESULT_VARIABLE code OUTPUT_VARIABLE out
                    ERROR_VARIABLE err)
    message("${out}${err}")
    if(NOT code EQUAL expect_code)
        message(FATAL_ERROR "facet chi2 ${ARGN}: exit code ${code}, expected ${expect_code}")
    endif()
    if(NOT out MATCHES "${expect_text}")
        message(FATAL_ERROR "facet chi2 ${ARGN}: output lacks \"${expect_text}\"")
    endif()
endfunction()

# A correct sampler passes and writes nothing unless asked to.
run_chi2(0 "verdict: accepted" bug=none)
if(EXISTS ${WORK}/chi2-failures)
    message(FATAL_ERROR "a passing test wrote ${WORK}/chi2-failures")
endif()

# --out writes the pictures even when the test passes.
run_chi2(0 "verdict: accepted" bug=none --out ${WORK}/out)
file(GLOB pictures ${WORK}/out/*.png)
list(LENGTH pictures n)
if(NOT n EQUAL 1)
    message(FATAL_ERROR "--out wrote ${n} pictures, expected 1")
endif()

# Wrong samplers are rejected: exit code 1, and the heat map and tables go to ./chi2-failures.
run_chi2(1 "verdict: REJECTED" bug=uniform)
run_chi2(1 "verdict: REJECTED" bug=scale --fixed)
file(GLOB pictures ${WORK}/chi2-failures/*.png)
file(GLOB tables ${WORK}/chi2-failures/*.txt)
list(LENGTH pictures np)
list(LENGTH tables nt)
if(NOT np EQUAL 2 OR NOT nt EQUAL 2)
    message(FATAL_ERROR "rejections wrote ${np} pictures and ${nt} tables, expected 2 and 2")
endif()
foreach(p ${pictures})
    file(SIZE ${p} size)
    if(size LESS 1000)
        message(FATAL_ERROR "${p} is only ${size} bytes")
    endif()
endforeach()

# Bad input is an error (exit code 1 with facet's one-line error), not a verdict.
run_chi2(1 "" bug=nonsense)

# Sizes that would not fit in memory are refused before anything is allocated, in one line that
# names the option (a bare "out of memory" used to name nothing).
function(expect_option_error expect_text)
    execute_process(COMMAND ${FACET} chi2 bsdf diffuse ${ARGN}
                    WORKING_DIRECTORY ${WORK} RESULT_VARIABLE code OUTPUT_VARIABLE out
                    ERROR_VARIABLE err)
    message("${out}${err}")
    string(REGEX MATCHALL "\n" newlines "${err}")
    list(LENGTH newlines lines)
    if(NOT code EQUAL 1 OR NOT lines EQUAL 1 OR NOT err MATCHES "^facet: error: ${expect_text}")
        message(FATAL_ERROR "facet chi2 bsdf diffuse ${ARGN}: exit code ${code}, expected 1 "
                            "and one line starting with \"facet: error: ${expect_text}\"")
    endif()
endfunction()
expect_option_error("--res 100000: the cells of the chi-square tables" --res 100000)
expect_option_error("--res 2000000000: " --res 2000000000)
expect_option_error("--samples 10000000000: expected 1 to 4294967295 samples"
                    --samples 10000000000)
# What the allocation limit refuses, it refuses naming the option too.
set(ENV{FACET_ALLOC_LIMIT_MB} 1)
expect_option_error("--res 256: .* exceed the allocation limit of 1.0 MiB" --res 256)
unset(ENV{FACET_ALLOC_LIMIT_MB})
