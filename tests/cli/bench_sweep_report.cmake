# gi-bench sweep on a tiny case (two techniques, two points), then gi-bench report: the CSV and
# JSON rows, a Markdown report with the front table, a rerun that measures nothing new, and a presets
# file with the three presets that gi-render --preset accepts.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
function(run_ok)
    execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
        message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
    endif()
    set(OUT "${out}" PARENT_SCOPE)
    set(ERR "${err}" PARENT_SCOPE)
endfunction()
set(SWEEP ${BENCH} sweep --scenes builtin:cornell-empty --size 32x32 --techniques none,rsm_gather --max-points 2
    --frames 1 --spp 4 --cache-dir ${WORK}/cache --out ${WORK}/sweep)
run_ok(${SWEEP})
if(NOT OUT MATCHES "measured 3 new points" OR NOT ERR MATCHES "\\[3/3\\] builtin:cornell-empty rsm_gather")
    message(FATAL_ERROR "expected 3 measured points with progress lines:\n${OUT}\n${ERR}")
endif()
file(STRINGS ${WORK}/sweep/sweep.csv csv)
list(LENGTH csv n)
if(NOT n EQUAL 4)
    message(FATAL_ERROR "sweep.csv should hold a header and 3 rows, has ${n} lines")
endif()
file(STRINGS ${WORK}/sweep/sweep.jsonl rows)
foreach(row ${rows})
    string(JSON rel GET "${row}" error relative_rmse)
    string(JSON ms GET "${row}" frame_ms)
    string(JSON indirect GET "${row}" error indirect relative_rmse_corrected)
    string(JSON noise GET "${row}" error indirect reference_noise)
    string(JSON direct GET "${row}" error direct relative_rmse)
    if(rel LESS_EQUAL 0 OR ms LESS_EQUAL 0 OR indirect LESS 0 OR noise LESS_EQUAL 0 OR direct LESS_EQUAL 0)
        message(FATAL_ERROR "implausible row: ${row}")
    endif()
endforeach()
# Resume: the same command measures nothing new.
run_ok(${SWEEP})
if(NOT OUT MATCHES "measured 0 new points" OR ERR MATCHES "measured again")
    message(FATAL_ERROR "the rerun measured again:\n${OUT}\n${ERR}")
endif()
# Against another reference the timings stand and only the errors are measured again.
run_ok(${BENCH} sweep --scenes builtin:cornell-empty --size 32x32 --techniques none,rsm_gather --max-points 2
       --frames 1 --spp 8 --cache-dir ${WORK}/cache --out ${WORK}/sweep)
string(REGEX MATCHALL "error measured again against this reference" again "${ERR}")
list(LENGTH again nAgain)
if(NOT OUT MATCHES "measured 0 new points" OR NOT nAgain EQUAL 3)
    message(FATAL_ERROR "a new reference should re-measure the 3 errors only:\n${OUT}\n${ERR}")
endif()
# A reference noisier than a fifth of the smallest error is rendered again (up to --spp), and the errors
# are measured again against it.
run_ok(${BENCH} sweep --scenes builtin:cornell-empty --size 32x32 --techniques rsm_gather --max-points 2
       --frames 1 --spp 2048 --noise-target 0.3 --cache-dir ${WORK}/cache --out ${WORK}/refine)
if(NOT ERR MATCHES "is above a fifth of the smallest error [0-9.]+: rendering it again to"
   OR NOT ERR MATCHES "error measured again against this reference")
    message(FATAL_ERROR "the noisy reference was not refined:\n${OUT}\n${ERR}")
endif()
run_ok(${BENCH} report --in ${WORK}/sweep --out ${WORK}/docs/accuracy.md --presets ${WORK}/presets.json)
file(READ ${WORK}/docs/accuracy.md md)
# Both rsm_gather points are within the reference's noise of each other at 32x32, so the front keeps
# whichever was faster in this run: the row names one of the two, not a fixed one.
foreach(expect "\\| technique \\| points \\| front point \\|" "\\| rsm_gather \\| 2 \\| (defaults|[a-z_]+=[0-9.]+) \\|"
        "Pareto front" "## Presets" "gi-bench sweep --scenes builtin:cornell-empty"
        "Reference `one-bounce-unoccluded` at 8 spp; its relative noise \\(from the samples' spread\\) is 0\\.[0-9]+ of the image"
        "indirect rel. RMSE \\| image rel. RMSE \\| direct pass" "more than a fifth of the smallest error")
    if(NOT md MATCHES "${expect}")
        message(FATAL_ERROR "accuracy.md lacks '${expect}':\n${md}")
    endif()
endforeach()
file(READ ${WORK}/presets.json presets)
foreach(name interactive balanced final)
    string(JSON p ERROR_VARIABLE e GET "${presets}" techniques rsm_gather ${name})
    if(e)
        message(FATAL_ERROR "presets.json lacks rsm_gather ${name}: ${e}\n${presets}")
    endif()
endforeach()
set(ENV{GI_PRESETS} ${WORK}/presets.json)
run_ok(${RENDER} --scene builtin:cornell-empty --technique rsm_gather --preset balanced --size 32x32 --quiet
       --stats ${WORK}/stats.json)
message(STATUS "ok")
