# Run with cmake -P: renders one peer scene at its test spp with every core and checks the image
# against Mitsuba 3's reference with `facet compare` (which prints the agreeing fraction and the
# relative error of the mean, and fails under 99.75 %, or when an image mean is more than 4
# standard errors from the reference's: a bias the per-pixel rule cannot see). The render and the z image stay in WORK.
# Inputs: -DFACET=<facet binary> -DNAME=<test name> -DSCENE=<scene file> -DMEAN=<reference mean>
#         -DVAR=<reference variance> -DSPP=<test spp> -DWORK=<scratch folder>
#         [-DMODE=<colour mode, facet render -m>]

foreach(v FACET NAME SCENE MEAN VAR SPP WORK)
    if(NOT DEFINED ${v})
        message(FATAL_ERROR "run_scene.cmake: ${v} is not set")
    endif()
endforeach()
file(MAKE_DIRECTORY ${WORK})
set(image ${WORK}/${NAME}.exr)
set(z_image ${WORK}/${NAME}_z.exr)
file(REMOVE ${image} ${z_image})

set(mode_args "")
if(DEFINED MODE)
    set(mode_args -m ${MODE})
endif()
message("facet render ${SCENE} ${mode_args} -D spp=${SPP} -o ${image}")
string(TIMESTAMP start "%s")
execute_process(COMMAND ${FACET} render ${SCENE} ${mode_args} -D spp=${SPP} -q -o ${image}
                RESULT_VARIABLE code)
string(TIMESTAMP end "%s")
math(EXPR seconds "${end} - ${start}")
if(NOT code EQUAL 0)
    message(FATAL_ERROR "${NAME}: facet render failed (exit code ${code})")
endif()
message("${NAME}: rendered in ${seconds} s")

message("facet compare ${image} ${MEAN} ${VAR} --spp ${SPP} --mean-sigmas 4 --z-image ${z_image}")
execute_process(COMMAND ${FACET} compare ${image} ${MEAN} ${VAR} --spp ${SPP} --mean-sigmas 4
                        --z-image ${z_image} RESULT_VARIABLE code)
if(NOT code EQUAL 0)
    message(FATAL_ERROR "${NAME}: the render does not agree with the peer's image "
                        "(facet compare exit code ${code}; z scores in ${z_image})")
endif()
