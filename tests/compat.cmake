# The compatibility suite (label compat): every scene of compat/data/peer-scenes rendered at its
# test spp and checked against Mitsuba 3's own image of it (compat/data/peer-renders) with
# `facet compare`, one ctest per line of compat/scenes.txt, and one per other colour mode with a
# reference in compat/data/peer-renders-modes (`<name>-mono`, `<name>-spectral`,
# `<name>-spectral_polarized`, labels compat-mono, compat-spectral, compat-spectral_polarized).
# A scene that
# needs a plugin that does not exist in plugins/ yet is registered DISABLED, with the missing
# plugins named (configure output, the test's FACET_MISSING_PLUGINS property and environment); it
# enables itself once they exist. compat/disabled.txt disables known gaps, each with its reason.
# Also the GoogleTest files in compat/ (the checks of `facet compare` itself).

if(NOT TARGET facet_cli)
    return()
endif()

facet_add_test_folder(compat)

set(FACET_COMPAT_DIR ${CMAKE_CURRENT_SOURCE_DIR}/compat)
set(FACET_COMPAT_SCENES ${FACET_COMPAT_DIR}/data/peer-scenes)
set(FACET_COMPAT_REFS ${FACET_COMPAT_DIR}/data/peer-renders)
# References in the other colour modes: <name>_<mode>_mean_rgb.exr, one test <name>-<mode> each.
set(FACET_COMPAT_MODE_REFS ${FACET_COMPAT_DIR}/data/peer-renders-modes)
set(FACET_COMPAT_MODES mono spectral spectral_polarized)
set(FACET_COMPAT_WORK ${CMAKE_BINARY_DIR}/tests/compat)
file(MAKE_DIRECTORY ${FACET_COMPAT_WORK})

# A plugin added or removed re-runs the configuration, so its scenes enable themselves.
file(GLOB _compat_plugin_sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/plugins/*/*.cpp)
file(GLOB_RECURSE _compat_xml CONFIGURE_DEPENDS ${FACET_COMPAT_SCENES}/*.xml)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${FACET_COMPAT_DIR}/scenes.txt)

# The plugin folder of each XML tag that names a plugin with type="...". Spectra with a type are
# textures, as in Mitsuba 3.
set(_compat_folder_bsdf bsdfs)
set(_compat_folder_emitter emitters)
set(_compat_folder_shape shapes)
set(_compat_folder_texture textures)
set(_compat_folder_spectrum textures)
set(_compat_folder_integrator integrators)
set(_compat_folder_sensor sensors)
set(_compat_folder_film films)
set(_compat_folder_sampler samplers)
set(_compat_folder_rfilter rfilters)
set(_compat_folder_medium media)
set(_compat_folder_phase phases)
set(_compat_folder_volume volumes)

# The text of an XML file without its comments.
function(_compat_read_xml file out)
    file(READ ${file} _text)
    while(TRUE)
        string(FIND "${_text}" "<!--" _begin)
        if(_begin EQUAL -1)
            break()
        endif()
        string(SUBSTRING "${_text}" ${_begin} -1 _rest)
        string(FIND "${_rest}" "-->" _end)
        if(_end EQUAL -1)
            message(FATAL_ERROR "compat: unterminated comment in ${file}")
        endif()
        math(EXPR _end "${_end} + 3")
        string(SUBSTRING "${_rest}" ${_end} -1 _rest)
        string(SUBSTRING "${_text}" 0 ${_begin} _head)
        set(_text "${_head}${_rest}")
    endwhile()
    set(${out} "${_text}" PARENT_SCOPE)
endfunction()

# The files a scene file includes (<include filename="..."/>, relative to the including file),
# recursively; `out` lists the scene file itself first.
function(_compat_scene_files file out)
    set(_todo ${file})
    set(_done "")
    while(_todo)
        list(POP_FRONT _todo _f)
        if(_f IN_LIST _done)
            continue()
        endif()
        if(NOT EXISTS ${_f})
            message(FATAL_ERROR "compat: ${file} includes ${_f}, which does not exist")
        endif()
        list(APPEND _done ${_f})
        get_filename_component(_dir ${_f} DIRECTORY)
        _compat_read_xml(${_f} _text)
        string(REGEX MATCHALL "<include[ \t\r\n][^>]*filename=\"[^\"]+\"" _incs "${_text}")
        foreach(_inc IN LISTS _incs)
            string(REGEX REPLACE ".*filename=\"([^\"]+)\"" "\\1" _inc "${_inc}")
            get_filename_component(_inc ${_inc} ABSOLUTE BASE_DIR ${_dir})
            list(APPEND _todo ${_inc})
        endforeach()
    endwhile()
    set(${out} ${_done} PARENT_SCOPE)
endfunction()

# The plugins (as "kind name") that a scene and its included files name but plugins/ lacks.
function(_compat_missing_plugins scene out)
    _compat_scene_files(${scene} _files)
    set(_missing "")
    foreach(_f IN LISTS _files)
        _compat_read_xml(${_f} _text)
        string(REGEX MATCHALL "<[A-Za-z_]+[ \t\r\n][^>]*type=\"[^\"]*\"" _tags "${_text}")
        foreach(_tag IN LISTS _tags)
            string(REGEX REPLACE "^<([A-Za-z_]+)[ \t\r\n].*" "\\1" _kind "${_tag}")
            string(REGEX REPLACE ".*[ \t\r\n]type=\"([^\"]*)\".*" "\\1" _name "${_tag}")
            set(_folder "${_compat_folder_${_kind}}")
            if(_folder STREQUAL "" OR NOT EXISTS ${PROJECT_SOURCE_DIR}/plugins/${_folder}/${_name}.cpp)
                set(_entry "${_kind} ${_name}")
                if(NOT _entry IN_LIST _missing)
                    list(APPEND _missing "${_entry}")
                endif()
            endif()
        endforeach()
    endforeach()
    set(${out} "${_missing}" PARENT_SCOPE)
endfunction()

# The suite must cover every reference and every scene file; a reference without a line in
# scenes.txt is a configuration error, not a test that silently does not exist.
file(GLOB _compat_means RELATIVE ${FACET_COMPAT_REFS} ${FACET_COMPAT_REFS}/*_mean_rgb.exr)
file(GLOB _compat_mode_means RELATIVE ${FACET_COMPAT_MODE_REFS}
     ${FACET_COMPAT_MODE_REFS}/*_mean_rgb.exr)
set(_compat_included "")
foreach(_f IN LISTS _compat_xml)
    _compat_scene_files(${_f} _files)
    list(POP_FRONT _files)
    list(APPEND _compat_included ${_files})
endforeach()

file(STRINGS ${FACET_COMPAT_DIR}/scenes.txt _compat_lines)
include(ProcessorCount)
ProcessorCount(_compat_cores)
if(_compat_cores LESS 1)
    set(_compat_cores 1)
endif()

set(_compat_names "")
set(_compat_mode_names "")
set(_compat_scenes "")
set(_compat_disabled 0)
foreach(_line IN LISTS _compat_lines)
    string(STRIP "${_line}" _line)
    if(_line STREQUAL "" OR _line MATCHES "^#")
        continue()
    endif()
    separate_arguments(_fields UNIX_COMMAND "${_line}")
    list(LENGTH _fields _n)
    if(NOT _n EQUAL 3)
        message(FATAL_ERROR "compat/scenes.txt: \"${_line}\": expected <name> <scene> <spp>")
    endif()
    list(GET _fields 0 _name)
    list(GET _fields 1 _scene_rel)
    list(GET _fields 2 _spp)
    set(_scene ${FACET_COMPAT_SCENES}/${_scene_rel})
    set(_mean ${FACET_COMPAT_REFS}/${_name}_mean_rgb.exr)
    set(_var ${FACET_COMPAT_REFS}/${_name}_var_xyz.exr)
    foreach(_f ${_scene} ${_mean} ${_var})
        if(NOT EXISTS ${_f})
            message(FATAL_ERROR "compat/scenes.txt: ${_name}: ${_f} does not exist")
        endif()
    endforeach()
    list(APPEND _compat_names ${_name})
    list(APPEND _compat_scenes ${_scene})

    add_test(NAME ${_name}
             COMMAND ${CMAKE_COMMAND} -DFACET=$<TARGET_FILE:facet_cli> -DNAME=${_name}
                     -DSCENE=${_scene} -DMEAN=${_mean} -DVAR=${_var} -DSPP=${_spp}
                     -DWORK=${FACET_COMPAT_WORK} -P ${FACET_COMPAT_DIR}/run_scene.cmake)
    # The render uses every core: the test counts as that many processors, so `ctest -jN` never
    # runs it beside other tests on the same cores.
    set_tests_properties(${_name} PROPERTIES LABELS compat PROCESSORS ${_compat_cores}
                         TIMEOUT 1800)

    set(_tests ${_name})
    # The same scene in each other mode with a reference.
    foreach(_mode IN LISTS FACET_COMPAT_MODES)
        set(_mode_mean ${FACET_COMPAT_MODE_REFS}/${_name}_${_mode}_mean_rgb.exr)
        set(_mode_var ${FACET_COMPAT_MODE_REFS}/${_name}_${_mode}_var_xyz.exr)
        if(NOT EXISTS ${_mode_mean})
            continue()
        endif()
        if(NOT EXISTS ${_mode_var})
            message(FATAL_ERROR "compat: ${_mode_mean} has no ${_mode_var}")
        endif()
        add_test(NAME ${_name}-${_mode}
                 COMMAND ${CMAKE_COMMAND} -DFACET=$<TARGET_FILE:facet_cli>
                         -DNAME=${_name}-${_mode} -DSCENE=${_scene} -DMEAN=${_mode_mean}
                         -DVAR=${_mode_var} -DSPP=${_spp} -DMODE=scalar_${_mode}
                         -DWORK=${FACET_COMPAT_WORK} -P ${FACET_COMPAT_DIR}/run_scene.cmake)
        set_tests_properties(${_name}-${_mode} PROPERTIES LABELS "compat;compat-${_mode}"
                             PROCESSORS ${_compat_cores} TIMEOUT 1800)
        list(APPEND _tests ${_name}-${_mode})
        list(APPEND _compat_mode_names ${_name}_${_mode})
    endforeach()

    _compat_missing_plugins(${_scene} _missing)
    if(_missing)
        string(REPLACE ";" ", " _missing "${_missing}")
        # The reason is a property of its own and, so that `ctest --show-only=json-v1` shows it,
        # also the test's environment (a disabled test never runs, so this sets nothing).
        foreach(_test IN LISTS _tests)
            set_tests_properties(${_test} PROPERTIES DISABLED TRUE
                                 FACET_MISSING_PLUGINS "${_missing}"
                                 ENVIRONMENT "FACET_MISSING_PLUGINS=${_missing}")
            message(STATUS "compat: ${_test} is disabled: it needs ${_missing}, not in plugins/")
            math(EXPR _compat_disabled "${_compat_disabled} + 1")
        endforeach()
    endif()
endforeach()

# Known gaps: DISABLED, with the reason printed at configure time and kept in the test's
# FACET_DISABLED_REASON property and environment.
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${FACET_COMPAT_DIR}/disabled.txt)
file(STRINGS ${FACET_COMPAT_DIR}/disabled.txt _compat_disabled_lines)
foreach(_line IN LISTS _compat_disabled_lines)
    if(_line STREQUAL "" OR _line MATCHES "^#")
        continue()
    endif()
    string(REGEX MATCH "^([^ ]+) +(.+)$" _ok "${_line}")
    if(NOT _ok)
        message(FATAL_ERROR "compat/disabled.txt: \"${_line}\": expected <test> <reason>")
    endif()
    set(_test ${CMAKE_MATCH_1})
    set(_why "${CMAKE_MATCH_2}")
    if(NOT TEST ${_test})
        message(FATAL_ERROR "compat/disabled.txt: ${_test} is no compat test")
    endif()
    set_tests_properties(${_test} PROPERTIES DISABLED TRUE FACET_DISABLED_REASON "${_why}"
                         ENVIRONMENT "FACET_DISABLED_REASON=${_why}")
    message(STATUS "compat: ${_test} is disabled: ${_why}")
    math(EXPR _compat_disabled "${_compat_disabled} + 1")
endforeach()

foreach(_m IN LISTS _compat_mode_means)
    string(REGEX REPLACE "_mean_rgb\\.exr$" "" _m "${_m}")
    if(NOT _m IN_LIST _compat_mode_names)
        message(FATAL_ERROR "compat: reference ${_m} (peer-renders-modes) has no line in "
                            "compat/scenes.txt, or its mode is not in FACET_COMPAT_MODES")
    endif()
endforeach()

foreach(_m IN LISTS _compat_means)
    string(REGEX REPLACE "_mean_rgb\\.exr$" "" _m "${_m}")
    if(NOT _m IN_LIST _compat_names)
        message(FATAL_ERROR "compat: reference ${_m} has no line in compat/scenes.txt")
    endif()
endforeach()
foreach(_f IN LISTS _compat_xml)
    if(NOT _f IN_LIST _compat_included AND NOT _f IN_LIST _compat_scenes)
        message(FATAL_ERROR "compat: scene ${_f} has no line in compat/scenes.txt")
    endif()
endforeach()

list(LENGTH _compat_names _compat_count)
list(LENGTH _compat_mode_names _compat_mode_count)
math(EXPR _compat_count "${_compat_count} + ${_compat_mode_count}")
math(EXPR _compat_enabled "${_compat_count} - ${_compat_disabled}")
message(STATUS "compat: ${_compat_count} peer scene renders, ${_compat_enabled} enabled, "
               "${_compat_disabled} disabled (waiting for plugins, or in compat/disabled.txt)")
