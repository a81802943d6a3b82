# Fuzz targets (tests/fuzz/<target>.cpp, each an LLVMFuzzerTestOneInput) and their replays.
# Their inputs are data, in tests/data/fuzz/<target>/: corpus/ (the seeds), grown/ (the inputs a
# longer campaign found, minimised with -merge=1; the next campaign starts from them),
# regressions/ (every input that once crashed the target) and, for xml, xml.dict.
# In every build: fuzz_<target>_replay runs the entry point over corpus/, grown/ and regressions/
# as the ctest fuzz.<target> (label fuzz).
# With -DFACET_FUZZ=ON (clang; implies FACET_SANITIZE): the libFuzzer executables
# fuzz_<target>, run as README.md describes.
set(FACET_FUZZ_TARGETS xml obj ply serialized image)
set(_fuzz_dir ${CMAKE_CURRENT_SOURCE_DIR}/fuzz)
set(_fuzz_data ${CMAKE_CURRENT_SOURCE_DIR}/data/fuzz)
foreach(t ${FACET_FUZZ_TARGETS})
    set(_libs facet facet_warnings OpenImageIO::OpenImageIO pugixml::pugixml)
    # The target's source is compiled once for both programs (with FACET_FUZZ, every source has
    # libFuzzer's coverage instrumentation; -fsanitize=fuzzer only adds libFuzzer at the link).
    add_library(fuzz_${t}_entry OBJECT ${_fuzz_dir}/${t}.cpp)
    target_link_libraries(fuzz_${t}_entry PRIVATE ${_libs})
    add_executable(fuzz_${t}_replay $<TARGET_OBJECTS:fuzz_${t}_entry> ${_fuzz_dir}/replay.cpp)
    target_link_libraries(fuzz_${t}_replay PRIVATE ${_libs})
    # The plugins and the image library are loaded at run time, not linked.
    add_dependencies(fuzz_${t}_replay facet_plugins facet_image facet_read)
    set(_inputs ${_fuzz_data}/${t}/corpus)
    foreach(_more grown regressions)
        if(EXISTS ${_fuzz_data}/${t}/${_more})
            list(APPEND _inputs ${_fuzz_data}/${t}/${_more})
        endif()
    endforeach()
    add_test(NAME fuzz.${t} COMMAND fuzz_${t}_replay ${_inputs}
             WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR})
    set_tests_properties(fuzz.${t} PROPERTIES LABELS fuzz TIMEOUT 300)
    if(FACET_SANITIZE AND t STREQUAL "image")
        # OpenImageIO's PNG reader leaks a string when libpng longjmps out of its read callback
        # (tests/data/fuzz/image/regressions/leak-png-*), suppressed by that frame in
        # .ci/lsan.supp. Neither OpenImageIO nor libstdc++ keeps frame pointers, so the fast
        # unwinder stops inside libstdc++ before that frame and the suppression cannot match:
        # unwind slowly here.
        set_tests_properties(fuzz.${t} PROPERTIES ENVIRONMENT_MODIFICATION
                             "ASAN_OPTIONS=string_append::fast_unwind_on_malloc=0")
    endif()
    if(FACET_FUZZ)
        add_executable(fuzz_${t} $<TARGET_OBJECTS:fuzz_${t}_entry>)
        target_link_options(fuzz_${t} PRIVATE -fsanitize=fuzzer)
        target_link_libraries(fuzz_${t} PRIVATE ${_libs})
        add_dependencies(fuzz_${t} facet_plugins facet_image facet_read)
    endif()
endforeach()
