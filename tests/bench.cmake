# `facet bench` (label bench): the equal-error mode (tests/bench/equal_error_test.sh) on the
# Cornell box, an environment-lit material scene and a large area light close to a floor
# (near-light), and the replay that measures Embree's share (tests/bench/embree_share_test.sh) on
# the first two, at tiny resolutions; `facet bench --suite` on a suite file of two scenes, one of
# them missing (tests/bench/suite_test.sh). tests/bench/make_ply.py writes the 1M-triangle PLY of
# the README's loading benchmark (not a test: it takes seconds).
if(TARGET facet_cli)
    foreach(scene cornell-box/scene.xml materials/rough-copper.xml near-light/scene.xml)
        get_filename_component(_name ${scene} NAME_WE)
        get_filename_component(_dir ${scene} DIRECTORY)
        add_test(NAME bench.equal_error.${_dir}
                 COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/bench/equal_error_test.sh
                         $<TARGET_FILE:facet_cli> ${PROJECT_SOURCE_DIR}/scenes/${scene}
                         ${CMAKE_CURRENT_BINARY_DIR}/bench-${_dir} -D res=24 -D max_depth=4)
        set_tests_properties(bench.equal_error.${_dir} PROPERTIES LABELS bench TIMEOUT 300)
    endforeach()
    foreach(scene cornell-box/scene.xml materials/rough-copper.xml)
        get_filename_component(_dir ${scene} DIRECTORY)
        add_test(NAME bench.embree_share.${_dir}
                 COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/bench/embree_share_test.sh
                         $<TARGET_FILE:facet_cli> ${PROJECT_SOURCE_DIR}/scenes/${scene}
                         -D res=32 -D max_depth=4)
        set_tests_properties(bench.embree_share.${_dir} PROPERTIES LABELS bench TIMEOUT 300)
    endforeach()
    # `facet bench --suite` (tests/bench/suite_test.sh): a tiny Cornell box and a missing scene.
    add_test(NAME bench.suite
             COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/bench/suite_test.sh $<TARGET_FILE:facet_cli>
                     ${PROJECT_SOURCE_DIR}/scenes ${CMAKE_CURRENT_BINARY_DIR}/bench-suite)
    set_tests_properties(bench.suite PROPERTIES LABELS bench TIMEOUT 60)
endif()

# The statistics counters and the recording and replay of Embree queries behind `facet bench`:
# one GoogleTest program on the code of the command (core/apps/ray_recording.cpp) and libfacet's
# private headers it uses (labels unit and bench: it takes a fraction of a second).
if(TARGET facet_cli)
    add_executable(bench_checks ${CMAKE_CURRENT_SOURCE_DIR}/bench/checks.cpp
                                ${PROJECT_SOURCE_DIR}/core/apps/ray_recording.cpp)
    target_include_directories(bench_checks PRIVATE ${PROJECT_SOURCE_DIR}/core/apps
                               ${PROJECT_SOURCE_DIR}/core/src)
    target_compile_options(bench_checks PRIVATE ${FACET_TEST_COMPILE_OPTIONS})
    target_link_libraries(bench_checks PRIVATE facet facet_warnings GTest::gtest GTest::gtest_main)
    add_dependencies(bench_checks facet_plugins)
    add_test(NAME bench.checks COMMAND bench_checks)
    set_tests_properties(bench.checks PROPERTIES LABELS "unit;bench" TIMEOUT 300)
endif()
