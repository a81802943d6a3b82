# facet_add_plugin(<name> <sources...>)
# Builds one loadable plugin: a MODULE library named exactly <name>.so (no "lib" prefix),
# linked against facet::core. Inside the facet tree the library goes to the build's plugin
# folder, is installed with the others and is appended to the FACET_PLUGINS list.
function(facet_add_plugin name)
    set(sources ${ARGN})
    if(NOT sources)
        message(FATAL_ERROR "facet_add_plugin(${name}): no sources given")
    endif()
    add_library(${name} MODULE ${sources})
    set_target_properties(${name} PROPERTIES PREFIX "" CXX_VISIBILITY_PRESET hidden)
    if(TARGET facet)
        # Building inside the facet source tree.
        target_link_libraries(${name} PRIVATE facet facet_warnings)
        set_target_properties(${name} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${FACET_PLUGIN_BUILD_DIR})
        install(TARGETS ${name} LIBRARY DESTINATION ${FACET_INSTALL_PLUGIN_DIR})
        set_property(GLOBAL APPEND PROPERTY FACET_PLUGINS ${name})
    else()
        target_link_libraries(${name} PRIVATE facet::core)
    endif()
endfunction()
