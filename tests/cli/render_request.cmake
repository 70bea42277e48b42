# gi-render --request (parseRenderRequest + executeRenderJob, the HTTP API's path) against the
# equivalent flags: byte-identical PNG and WebP files, stdin input, the stats' encoding fields, and
# exit code 2 with the JSON pointer for a bad request or a conflicting flag. 64x64, 16 VPLs.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

function(run_ok)
    execute_process(COMMAND ${RENDER} ${ARGN} --quiet RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
        message(FATAL_ERROR "gi-render ${ARGN} failed (${rc}): ${err}")
    endif()
endfunction()

function(expect_same a b)
    execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/${a} ${WORK}/${b} RESULT_VARIABLE differ)
    if(differ)
        file(SIZE ${WORK}/${a} size_a)
        file(SIZE ${WORK}/${b} size_b)
        message(FATAL_ERROR "${a} (${size_a} bytes) and ${b} (${size_b} bytes) differ")
    endif()
endfunction()

set(params "\"vpl_grid\": 4, \"exposure\": 0.5")
file(WRITE ${WORK}/png.json
     "{\"scene\": \"builtin:cornell\", \"technique\": \"rsm_gather\", \"params\": {${params}}, \"size\": [64, 64]}")
set(flags --scene builtin:cornell --technique rsm_gather --param vpl_grid=4 --param exposure=0.5 --size 64x64)

run_ok(--request ${WORK}/png.json --out ${WORK}/request.png --stats ${WORK}/request.json)
run_ok(${flags} --out ${WORK}/flags.png)
expect_same(request.png flags.png)

execute_process(COMMAND ${RENDER} --request - --out ${WORK}/stdin.png --quiet INPUT_FILE ${WORK}/png.json
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "gi-render --request - failed (${rc}): ${err}")
endif()
expect_same(request.png stdin.png)

file(READ ${WORK}/request.json stats)
string(JSON codec GET "${stats}" codec)
string(JSON bytes GET "${stats}" bytes)
string(JSON vpls GET "${stats}" counts vpl_count)
file(SIZE ${WORK}/request.png size)
if(NOT codec STREQUAL "png" OR NOT bytes EQUAL size OR NOT vpls EQUAL 16)
    message(FATAL_ERROR "unexpected stats: codec=${codec} bytes=${bytes} (file ${size}) vpl_count=${vpls}")
endif()

file(WRITE ${WORK}/webp.json "{\"scene\": \"builtin:cornell\", \"params\": {${params}}, \"size\": [64, 64], \
\"format\": \"webp\", \"quality\": 80}")
run_ok(--request ${WORK}/webp.json --out ${WORK}/request.webp)
run_ok(${flags} --quality 80 --out ${WORK}/flags.webp)
expect_same(request.webp flags.webp)

function(expect_usage_error expected)
    execute_process(COMMAND ${RENDER} ${ARGN} RESULT_VARIABLE rc ERROR_VARIABLE err)
    string(FIND "${err}" "${expected}" at)
    if(NOT rc EQUAL 2 OR at EQUAL -1)
        message(FATAL_ERROR "gi-render ${ARGN}: exit ${rc}, expected 2 and '${expected}' in: ${err}")
    endif()
endfunction()

file(WRITE ${WORK}/bad.json "{\"scene\": \"builtin:cornell\", \"size\": [8, 64]}")
expect_usage_error("/size/0: must be >= 16" --request ${WORK}/bad.json)
expect_usage_error("--scene cannot be used with --request" --request ${WORK}/png.json --scene builtin:cornell)
expect_usage_error("does not match the request's format 'png'" --request ${WORK}/png.json --out ${WORK}/x.jpg)
message(STATUS "ok")
