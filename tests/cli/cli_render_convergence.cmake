# `weft render --convergence auto` (docs/render.md §6b, supplement Figs. S.6–S.8) on the example scenes with
# exponential, linear-law (negatively correlated) and gamma-law (positively correlated) media.
# Included by tests/cli/CMakeLists.txt (adds the tests) and run as a script for one case:
#   cmake -DWEFT=... -DSCENE=cornell_linear -DWORK=... [-DSLOW=ON] -P cli_render_convergence.cmake
#
# Checks the outputs for content: the CSV's columns and one row per power of two up to the
# series' spp; the fitted RMSE-vs-spp slope within 0.1 of the Monte Carlo rate −1/2 (the fit
# spans 2..128 spp, ln 64 ≈ 4.2: a 5% error in the RMSE at either end moves the slope by
# 2·0.05/4.2 ≈ 0.024, so 0.1 is about four such errors, and a rate of −1/4 or −1 fails);
# a non-empty contact-sheet PNG of the 2, 8, 64, 128 (and 512 when slow) spp images.

if(CMAKE_SCRIPT_MODE_FILE)
  file(REMOVE_RECURSE ${WORK})
  file(MAKE_DIRECTORY ${WORK})
  if(SLOW)
    set(spp 512)
    set(expected_sheet "2,8,64,128,512")
    set(extra --spp 512 --reference-spp 8192)
  else()
    set(spp 128)
    set(expected_sheet "2,8,64,128")
    set(extra "")
  endif()
  execute_process(COMMAND ${WEFT} render ${SCENE} --quick --convergence auto ${extra} -o ${WORK}/run.exr
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "convergence run failed (${rc}): ${err}")
  endif()
  message(STATUS "${out}")
  foreach(f run.exr run.png run.reference.exr run.convergence.csv run.convergence.json run.contact.png)
    if(NOT EXISTS ${WORK}/${f})
      message(FATAL_ERROR "missing output ${f}")
    endif()
  endforeach()
  file(SIZE ${WORK}/run.contact.png sheet_size)
  if(sheet_size LESS 100)
    message(FATAL_ERROR "contact sheet is ${sheet_size} bytes")
  endif()
  # CSV: header, then spp 1, 2, 4, ..., spp with finite, positive errors.
  file(STRINGS ${WORK}/run.convergence.csv rows)
  list(GET rows 0 header)
  if(NOT header STREQUAL "spp,seconds,rmse,rmse_corrected")
    message(FATAL_ERROR "unexpected CSV header '${header}'")
  endif()
  list(REMOVE_AT rows 0)
  set(expect_spp 1)
  foreach(row ${rows})
    string(REPLACE "," ";" cells "${row}")
    list(LENGTH cells ncells)
    list(GET cells 0 row_spp)
    list(GET cells 2 row_rmse)
    if(NOT ncells EQUAL 4 OR NOT row_spp EQUAL expect_spp OR NOT row_rmse GREATER 0)
      message(FATAL_ERROR "bad CSV row '${row}' (expected spp ${expect_spp}, 4 cells, rmse > 0)")
    endif()
    math(EXPR expect_spp "${expect_spp} * 2")
  endforeach()
  math(EXPR last "${expect_spp} / 2")
  if(NOT last EQUAL spp)
    message(FATAL_ERROR "CSV ends at ${last} spp, expected ${spp}")
  endif()
  file(READ ${WORK}/run.convergence.json summary)
  string(JSON slope GET "${summary}" slope_vs_spp)
  string(JSON sheet GET "${summary}" contact_sheet_spp)
  string(REGEX REPLACE "[][ \n]" "" sheet "${sheet}")
  if(NOT sheet STREQUAL expected_sheet)
    message(FATAL_ERROR "contact sheet shows spp ${sheet}, expected ${expected_sheet}")
  endif()
  if(NOT (slope GREATER -0.6 AND slope LESS -0.4))
    message(FATAL_ERROR "RMSE slope vs spp ${slope} is not within 0.1 of -0.5")
  endif()
  # The chart (when a display was found): RMSE vs spp (blue) left, RMSE vs seconds (red) right,
  # each on its own axis and only in its own panel.
  if(EXISTS ${WORK}/run.convergence.png AND PROBE)
    foreach(probe "31,119,180|0,0,0.5,1|0.5,0,1,1" "214,39,40|0.5,0,1,1|0,0,0.5,1")
      string(REPLACE "|" ";" parts "${probe}")
      list(GET parts 0 rgb)
      list(GET parts 1 inside)
      list(GET parts 2 outside)
      execute_process(COMMAND "${PROBE}" ${WORK}/run.convergence.png ${rgb} --region ${inside} --min-columns 150
                      RESULT_VARIABLE prc OUTPUT_VARIABLE pout)
      if(NOT prc EQUAL 0)
        message(FATAL_ERROR "run.convergence.png: colour ${rgb} not drawn across ${inside}: ${pout}")
      endif()
      execute_process(COMMAND "${PROBE}" ${WORK}/run.convergence.png ${rgb} --region ${outside} --min-pixels 0
                              --max-pixels 0 RESULT_VARIABLE prc OUTPUT_VARIABLE pout)
      if(NOT prc EQUAL 0)
        message(FATAL_ERROR "run.convergence.png: colour ${rgb} in the other panel ${outside}: ${pout}")
      endif()
    endforeach()
  endif()
  # The contact sheet: --quick's 48 px images enlarged to >= 192 px each (noise visible), and a
  # black caption ("N spp") under each of them, in the bottom strip of every tile's column.
  if(PROBE)
    execute_process(COMMAND "${PROBE}" ${WORK}/run.contact.png 0,0,0 --tol 60 --region 0,0.8,1,1 --min-pixels 1
                    RESULT_VARIABLE prc OUTPUT_VARIABLE pout)
    if(NOT prc EQUAL 0)
      message(FATAL_ERROR "run.contact.png: no captions in the bottom strip: ${pout}")
    endif()
    string(REGEX MATCH "width ([0-9]+)" _ "${pout}")
    set(sheet_width ${CMAKE_MATCH_1})
    string(REPLACE "," ";" sheet_list "${expected_sheet}")
    list(LENGTH sheet_list n_tiles)
    math(EXPR min_width "${n_tiles} * 192")
    if(sheet_width LESS min_width)
      message(FATAL_ERROR "run.contact.png is ${sheet_width} px wide for ${n_tiles} images: not enlarged")
    endif()
    math(EXPR last "${n_tiles} - 1")
    foreach(i RANGE ${last})
      # Fractions with three decimals (1000ths, zero-padded): the i-th of n equal columns.
      math(EXPR left_pm "1000 + 1000 * ${i} / ${n_tiles}")
      math(EXPR right_pm "1000 + 1000 * (${i} + 1) / ${n_tiles}")
      string(SUBSTRING ${left_pm} 1 3 left_frac)
      string(SUBSTRING ${right_pm} 1 3 right_frac)
      set(right "0.${right_frac}")
      if(right_pm EQUAL 2000)
        set(right 1)
      endif()
      execute_process(COMMAND "${PROBE}" ${WORK}/run.contact.png 0,0,0 --tol 60
                              --region 0.${left_frac},0.8,${right},1 --min-pixels 10
                      RESULT_VARIABLE prc OUTPUT_VARIABLE pout)
      if(NOT prc EQUAL 0)
        message(FATAL_ERROR "run.contact.png: image ${i} has no caption: ${pout}")
      endif()
    endforeach()
  endif()
  message(STATUS "${SCENE}: slope vs spp ${slope}")
  return()
endif()

set(_convergence_work ${CMAKE_CURRENT_BINARY_DIR}/render_convergence)
foreach(scene cornell_exponential cornell_linear cornell_gamma)
  add_test(NAME cli.render_convergence.${scene}
           COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> -DPROBE=$<TARGET_FILE:png_probe> -DSCENE=${scene}
                   -DWORK=${_convergence_work}/${scene}
                   -P ${CMAKE_CURRENT_LIST_FILE})
  set_tests_properties(cli.render_convergence.${scene} PROPERTIES LABELS "cli;render" TIMEOUT 120)
  add_test(NAME cli.render_convergence.${scene}_slow
           COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> -DPROBE=$<TARGET_FILE:png_probe> -DSCENE=${scene} -DSLOW=ON
                   -DWORK=${_convergence_work}/${scene}_slow -P ${CMAKE_CURRENT_LIST_FILE})
  set_tests_properties(cli.render_convergence.${scene}_slow PROPERTIES LABELS "cli;render;slow" TIMEOUT 1200)
endforeach()
