# The plugin SDK test (label sdk): install this build into a scratch prefix, build tests/sdk/phong,
# tests/sdk/plain and a `facet new-plugin` project of every kind out of tree against it,
# render and chi2-test them with the installed `facet`. See tests/sdk/run_sdk_test.cmake.
if(NOT TARGET facet_cli)
    return()
endif()
set(_sdk_launcher "")
if(CMAKE_CXX_COMPILER_LAUNCHER)
    set(_sdk_launcher -DLAUNCHER=${CMAKE_CXX_COMPILER_LAUNCHER})
endif()
# The templates' parameter tables are checked by the unit test that checks facet's own.
add_test(NAME sdk.out_of_tree_plugins
         COMMAND ${CMAKE_COMMAND} -DBUILD_DIR=${CMAKE_BINARY_DIR} -DSOURCE_DIR=${PROJECT_SOURCE_DIR}
                 -DWORK=${CMAKE_BINARY_DIR}/tests/sdk -DCXX=${CMAKE_CXX_COMPILER} ${_sdk_launcher}
                 -DDOCS_TEST=$<TARGET_FILE:unit_plugin_docs>
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/sdk/run_sdk_test.cmake)
set_tests_properties(sdk.out_of_tree_plugins PROPERTIES LABELS sdk TIMEOUT 600)
