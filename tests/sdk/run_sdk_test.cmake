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

# Configure and build one out-of-tree project against the installed package (ARGN: more
# configure arguments).
function(build_project src bin)
    set(extra ${ARGN})
    if(LAUNCHER)
        list(APPEND extra -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
    endif()
    step("configure ${src}" ${CMAKE_COMMAND} -S ${src} -B ${bin} -DCMAKE_PREFIX_PATH=${PREFIX}
         -DCMAKE_CXX_COMPILER=${CXX} ${extra})
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
build_project(${SOURCE_DIR}/tests/sdk/phong ${WORK}/phong-build -DCMAKE_BUILD_TYPE=Release)
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

# An area light without constant_radiance() and a sampler that does not expose its generator,
# written against the interfaces alone, render the images facet's own `area` and `independent`
# render: the shortcuts for constant lights (meshes and other shapes) and PCG32 samplers change
# nothing a user's plugin can see.
build_project(${SOURCE_DIR}/tests/sdk/plain ${WORK}/plain-build -DCMAKE_BUILD_TYPE=Release)
step("plain plugins against facet's" ${WORK}/plain-build/plain_check
     ${SOURCE_DIR}/tests/sdk/plain/scene.xml ${WORK}/plain-build)

# 3. The templates: `facet new-plugin <kind>` writes a project that builds (optimised without
# being asked), lists its parameter table, renders the scene it comes with and, for the kinds
# facet's chi2 tests, passes chi2.
set(_template_dirs "")
set(_kinds bsdf emitter texture integrator shape sensor sampler film rfilter)
foreach(kind ${_kinds})
    set(name my${kind})
    set(project ${WORK}/${name})
    set(bin ${WORK}/${name}-build)
    step("new-plugin ${kind}" ${FACET} new-plugin ${kind} ${name} ${project})
    build_project(${project} ${bin}) # no CMAKE_BUILD_TYPE: the template picks Release
    file(STRINGS ${bin}/CMakeCache.txt _type REGEX "^CMAKE_BUILD_TYPE:")
    if(NOT _type MATCHES "=Release$")
        message(FATAL_ERROR "the ${kind} template builds as \"${_type}\", not Release")
    endif()
    if(NOT EXISTS ${bin}/${name}.so)
        message(FATAL_ERROR "the ${kind} template's build made no ${name}.so")
    endif()
    step("parameter table of the ${kind} template" ${FACET} plugins ${name} -a ${bin})
    set(_row_bsdf "\\| reflectance \\| spectrum or texture \\| 0.5 \\|")
    set(_row_emitter "\\| bottom \\| spectrum \\| 0.25 \\|")
    set(_row_texture "\\| scale \\| float \\| 1 \\|")
    set(_row_integrator "\\| max_distance \\| float \\| -1 \\|")
    set(_row_shape "\\| height \\| float \\| 1 \\|")
    set(_row_sensor "\\| fov \\| float \\| 40 \\|")
    set(_row_sampler "\\| sample_count \\| integer \\| 4 \\|")
    set(_row_film "\\| exposure \\| float \\| 0 \\|")
    set(_row_rfilter "\\| radius \\| float \\| 1.5 \\|")
    if(NOT STEP_OUTPUT MATCHES "${_row_${kind}}")
        message(FATAL_ERROR "`facet plugins ${name}` does not show the template's table")
    endif()
    file(REMOVE ${WORK}/${name}.exr)
    step("render the ${kind} template's scene" ${FACET} render ${project}/scene.xml -a ${bin}
         -o ${WORK}/${name}.exr -q -D spp=4)
    if(NOT EXISTS ${WORK}/${name}.exr)
        message(FATAL_ERROR "the render of the ${kind} template's scene wrote no image")
    endif()
    if(kind STREQUAL "bsdf")
        step("chi2 of the bsdf template" ${FACET} chi2 bsdf ${name} -a ${bin})
        step("chi2 of the bsdf template, grazing" ${FACET} chi2 bsdf ${name} -a ${bin} --theta 80
             --tests 2)
    elseif(kind STREQUAL "emitter")
        step("chi2 of the emitter template" ${FACET} chi2 emitter ${name} -a ${bin} --tests 2)
        step("chi2 of the emitter template, another point" ${FACET} chi2 emitter ${name}
             top=2,1,0.5 bottom=0 --ref 3,-1,0.2 -a ${bin} --tests 2)
    endif()
    list(APPEND _template_dirs ${bin})
endforeach()
# Every parameter each template's constructor reads is a row of its table: facet's own check of
# its plugins (PluginDocs), run with the templates on the plugin path.
if(DOCS_TEST)
    string(REPLACE ";" ":" _path "${_template_dirs}")
    step("plugins on the path of the check" ${CMAKE_COMMAND} -E env FACET_PLUGIN_PATH=${_path}
         ${FACET} plugins)
    foreach(kind ${_kinds})
        if(NOT STEP_OUTPUT MATCHES "my${kind}")
            message(FATAL_ERROR "my${kind} is not on the plugin path of the check")
        endif()
    endforeach()
    step("parameter tables of the templates" ${CMAKE_COMMAND} -E env FACET_PLUGIN_PATH=${_path}
         ${DOCS_TEST} --gtest_filter=PluginDocs.*)
else()
    message(FATAL_ERROR "run_sdk_test.cmake: DOCS_TEST (the unit_plugin_docs executable) is not set")
endif()

# 4. The build tree is a CMake package too: a plugin built against it (CMAKE_PREFIX_PATH=<build>)
# loads in the build's own `facet`.
build_project(${SOURCE_DIR}/tests/sdk/phong ${WORK}/phong-buildtree -DCMAKE_BUILD_TYPE=Release
              -DCMAKE_PREFIX_PATH=${BUILD_DIR})
file(STRINGS ${WORK}/phong-buildtree/CMakeCache.txt _dir REGEX "^facet_DIR:")
if(NOT _dir STREQUAL "facet_DIR:PATH=${BUILD_DIR}/lib/cmake/facet")
    message(FATAL_ERROR "the build-tree project found facet at \"${_dir}\", not in ${BUILD_DIR}")
endif()
step("render with the build tree's plugin" ${BUILD_DIR}/bin/facet render
     ${SOURCE_DIR}/tests/sdk/phong/scene.xml -a ${WORK}/phong-buildtree -o ${WORK}/phong3.exr -q
     -D spp=1)
if(NOT EXISTS ${WORK}/phong3.exr)
    message(FATAL_ERROR "the render with the build tree's plugin wrote no image")
endif()
