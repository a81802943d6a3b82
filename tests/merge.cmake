# `facet merge` and the README's Slurm recipe (label merge): shell scripts in tests/merge that
# render small crop and pass splits of the Cornell box with the facet command and compare the
# merges with idiff (OpenImageIO's tools).
find_program(FACET_IDIFF idiff)
if(TARGET facet_cli AND FACET_IDIFF)
    add_test(NAME merge.cli
             COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/merge/merge_test.sh $<TARGET_FILE:facet_cli>
                     ${PROJECT_SOURCE_DIR}/scenes/cornell-box/scene.xml
                     ${CMAKE_CURRENT_BINARY_DIR}/merge-cli)
    add_test(NAME merge.slurm_recipe
             COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/merge/slurm_recipe_test.sh
                     $<TARGET_FILE:facet_cli> ${PROJECT_SOURCE_DIR}/README.md
                     ${PROJECT_SOURCE_DIR}/scenes/cornell-box/scene.xml
                     ${CMAKE_CURRENT_BINARY_DIR}/merge-slurm)
    set_tests_properties(merge.cli merge.slurm_recipe PROPERTIES LABELS merge TIMEOUT 600)
elseif(TARGET facet_cli)
    message(WARNING "idiff (openimageio-tools) not found: the merge tests are not registered")
endif()

# What the merge refuses in the parts themselves (non-finite values, display windows the parts
# do not cover, named allocations): one GoogleTest program on libfacet's merge (facet/merge.h).
add_executable(merge_checks ${CMAKE_CURRENT_SOURCE_DIR}/merge/checks.cpp)
target_compile_options(merge_checks PRIVATE ${FACET_TEST_COMPILE_OPTIONS})
target_link_libraries(merge_checks PRIVATE facet facet_warnings GTest::gtest GTest::gtest_main)
add_test(NAME merge.checks COMMAND merge_checks)
set_tests_properties(merge.checks PROPERTIES LABELS merge TIMEOUT 300)
