# Test-only plugin libraries for unit_registry. They are built like plugins (MODULE, no "lib"
# prefix) but on purpose NOT with facet_add_plugin(), so they stay out of the plugin folder.
set(FACET_TEST_PLUGIN_DIR ${CMAKE_BINARY_DIR}/tests/plugins_bad)
if(TARGET unit_registry)
    foreach(name badabi wrongkind nosymbol misnamed testgood)
        add_library(test_plugin_${name} MODULE ${CMAKE_CURRENT_SOURCE_DIR}/plugins_bad/${name}.cpp)
        set_target_properties(test_plugin_${name} PROPERTIES
            PREFIX "" OUTPUT_NAME ${name} CXX_VISIBILITY_PRESET hidden
            LIBRARY_OUTPUT_DIRECTORY ${FACET_TEST_PLUGIN_DIR})
        target_link_libraries(test_plugin_${name} PRIVATE facet facet_warnings)
        add_dependencies(unit_registry test_plugin_${name})
    endforeach()
    target_compile_definitions(unit_registry PRIVATE
        FACET_TEST_PLUGIN_DIR="${FACET_TEST_PLUGIN_DIR}")
    target_link_libraries(unit_registry PRIVATE ${CMAKE_DL_LIBS})
    # The CLI tests list testgood, a plugin of the rgb and mono modes only.
    if(TARGET render_cli)
        add_dependencies(render_cli test_plugin_testgood)
        target_compile_definitions(render_cli PRIVATE
            FACET_TEST_PLUGIN_DIR="${FACET_TEST_PLUGIN_DIR}")
    endif()
endif()
