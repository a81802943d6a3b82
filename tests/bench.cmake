# `facet bench` (label bench): the equal-error mode (tests/bench/equal_error_test.sh) on the
# Cornell box, an environment-lit material scene and a large area light close to a floor
# (near-light), and the replay that measures Embree's share (tests/bench/embree_share_test.sh) on
# the first two, at tiny resolutions. tests/bench/make_ply.py writes the 1M-triangle PLY of the
# README's loading benchmark (not a test: it takes seconds).
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
endif()
