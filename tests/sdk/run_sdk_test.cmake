# Run with cmake -P by the `sdk` ctest: installs the facet build into a scratch prefix, builds
# plugins out of tree against that installation exactly as a user would, and checks that the
# installed `facet` loads them with -a (render and chi2) and that a test program of the plugin's
# author links the installed facet::testing.
# Inputs: -DBUILD_DIR=<facet build> -DSOURCE_DIR=<facet source> -DWORK=<scratch folder>
#         -DCXX=<C++ compiler> [-DLAUNCHER=<compiler launcher, e.g. ccache>]

foreach(v BUILD_DIR SOURCE_DIR WORK CXX)
    if(NOT DEFINED ${v})
        message(FATAL_ERROR "run_sdk_test.cmake: ${v} is not set")
    endif()
endforeach()
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(PREFIX ${WORK}/prefix)
set(FACET ${PREFIX}/bin/facet)

function(step what)
    message("-- ${what}: ${ARGN}")
    execute_process(COMMAND ${ARGN} WORKING_DIRECTORY ${WORK} RESULT_VARIABLE code
                    OUTPUT_VARIABLE out ERROR_VARIABLE err)
    message("${out}${err}")
    if(NOT code EQUAL 0)
        message(FATAL_ERROR "${what} failed (exit code ${code})")
    endif()
    set(STEP_OUTPUT "${out}" PARENT_SCOPE)
endfunction()

# Configure and build one out-of-tree project against the installed package.
function(build_project src bin)
    set(extra "")
    if(LAUNCHER)
        list(APPEND extra -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
    endif()
    step("configure ${src}" ${CMAKE_COMMAND} -S ${src} -B ${bin} -DCMAKE_PREFIX_PATH=${PREFIX}
         -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${CXX} ${extra})
    step("build ${src}" ${CMAKE_COMMAND} --build ${bin})
endfunction()

# 1. The installation: headers, libfacet, plugins, the command and the CMake package.
step("install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${PREFIX})
foreach(f bin/facet include/facet/bsdf.h include/facet/plugin.h include/facet/chi2.h
          include/facet/compare.h lib/cmake/facet/facetConfig.cmake
          lib/cmake/facet/FacetPlugin.cmake lib/facet/plugins/diffuse.so)
    if(NOT EXISTS ${PREFIX}/${f})
        message(FATAL_ERROR "the installation lacks ${f}")
    endif()
endforeach()

# 2. A BSDF that facet does not ship (modified Phong), built out of tree.
build_project(${SOURCE_DIR}/tests/sdk/phong ${WORK}/phong-build)
if(NOT EXISTS ${WORK}/phong-build/phong.so)
    message(FATAL_ERROR "the out-of-tree build made no phong.so")
endif()
step("parameter table" ${FACET} plugins phong -a ${WORK}/phong-build)
if(NOT STEP_OUTPUT MATCHES "\\| exponent \\| float \\| 30 \\|")
    message(FATAL_ERROR "`facet plugins phong` does not show the plugin's parameter table")
endif()
step("render with the plugin" ${FACET} render ${SOURCE_DIR}/tests/sdk/phong/scene.xml
     -a ${WORK}/phong-build -o ${WORK}/phong.exr -q)
if(NOT EXISTS ${WORK}/phong.exr)
    message(FATAL_ERROR "the render wrote no image")
endif()
step("chi2 of the plugin" ${FACET} chi2 bsdf phong -a ${WORK}/phong-build --theta 40 --tests 2)
step("chi2 of the plugin, sharp lobe" ${FACET} chi2 bsdf phong exponent=300
     specular_reflectance=0.6 diffuse_reflectance=0.3 -a ${WORK}/phong-build --theta 70 --tests 2)
# The plugin's own test program, linked against the installed facet::testing.
step("chi2 through facet::testing" ${WORK}/phong-build/phong_chi2 ${WORK}/phong-build)
if(NOT STEP_OUTPUT MATCHES "verdict: accepted")
    message(FATAL_ERROR "phong_chi2 printed no accepted verdict")
endif()
# $FACET_PLUGIN_PATH works as well as -a.
step("render through FACET_PLUGIN_PATH" ${CMAKE_COMMAND} -E env FACET_PLUGIN_PATH=${WORK}/phong-build
     ${FACET} render ${SOURCE_DIR}/tests/sdk/phong/scene.xml -o ${WORK}/phong2.exr -q -D spp=1)

# 3. The template: `facet new-plugin` writes a project that builds, loads and passes chi2.
step("new-plugin" ${FACET} new-plugin bsdf myplug ${WORK}/myplug)
build_project(${WORK}/myplug ${WORK}/myplug-build)
step("chi2 of the template" ${FACET} chi2 bsdf myplug -a ${WORK}/myplug-build)
