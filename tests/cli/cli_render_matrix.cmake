# `weft render --study` with no scene: the study matrix (docs/render.md §6e).
# Included by tests/cli/CMakeLists.txt (adds the tests) and run as a script for one case:
#   cmake -DWEFT=... -DWORK=... -DCASE=quick|same_bytes [-DMPIEXEC=... -DMPIFLAGS=...] -P cli_render_matrix.cmake
#
# quick: 2 cloths x 2 light set-ups x 1 view at 32x24 px, factors 2 and 4, 8 spp (--quick).
#   Per case, the bias estimates are statistical statements with standard errors: the fine grid
#   (the reference's own model) is consistent with no bias (|z| < 5 over the cloth's pixels) and
#   every candidate whose cloth bias is detectable (z > 5) is more biased than the fine grid; the
#   memory columns agree with what each representation is: 1 channel for the grids, the 4 of the
#   local fields file the medium reads on the same blocks as the downsampled grid (its mean as a
#   float, its three variances as half floats: 2.5x the downsampled grid's bytes),
#   the slab's 3 law parameters. Then a rerun with --resume takes every case from the store and
#   writes the same aggregate files byte for byte, and --resume with another spec is refused
#   (exit 1). The exponential candidates are split into transmission, single and multiple
#   scattering (--study-components): check_matrix_split.py asserts the fine grid's bias at every
#   image scale and in every component is 0 within 5 standard errors, only the asked candidates are
#   split, and the components' levels add up to the full one.
# distance: scripts/study_distance runs the quick matrix at 1 and 2 yarns and tabulates it;
#   check_study_distance.py asserts its rows are the runs' own figures and that a block's
#   footprint falls when the same film frames twice the yarns; bad options of the script end in one
#   line and exit 2 before any run, a missing run in exit 1 and no table.
# same_bytes: the same small matrix without mpirun and under mpirun -n 2 (one thread each) gives
#   the same matrix.csv, the same images of every case and the same matrix.json without timings.

if(CMAKE_SCRIPT_MODE_FILE)
  file(REMOVE_RECURSE ${WORK})
  file(MAKE_DIRECTORY ${WORK})
  set(args render --study --quick --study-factors 2,4 --study-cloths plain,stockinette --study-lightings back,front
           --study-tilts 45 --seed 3 --study-components exponential)
  if(CASE STREQUAL "quick")
    execute_process(COMMAND ${WEFT} ${args} --out ${WORK}/run RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "matrix failed (${rc}): ${err}")
    endif()
    message(STATUS "${out}")
    set(d ${WORK}/run)
    foreach(f matrix.csv matrix.cost.csv matrix.json matrix.md cases/plain-back-45deg/reference.exr
              cases/stockinette-front-45deg/reference.study.csv cases/stockinette-front-45deg/reference.study.contact.png
              cases/plain-front-45deg/study/local-gamma-segment-4x.exr)
      if(NOT EXISTS ${d}/${f})
        message(FATAL_ERROR "missing output ${f}")
      endif()
    endforeach()
    file(STRINGS ${d}/matrix.csv rows)
    list(GET rows 0 header)
    string(REPLACE "," ";" columns "${header}")
    foreach(col case candidate cloth_bias cloth_bias_z memory_bytes memory_channels cloth_bias_2px cloth_bias_4px_z
                cloth_level cloth_level_stderr transmission_bias single_bias_z multiple_difference)
      list(FIND columns ${col} i_${col})
      if(i_${col} LESS 0)
        message(FATAL_ERROR "matrix.csv lacks column ${col}: ${header}")
      endif()
    endforeach()
    list(REMOVE_AT rows 0)
    list(LENGTH rows n_rows)
    # 4 cases x (fine, 2 factors x (exponential, local-gamma (optical-depth), local-gamma-segment,
    # shadow-corrected, shadow-directional, albedo-corrected), slab): docs/render.md §6c–§6e.
    if(NOT n_rows EQUAL 56)
      message(FATAL_ERROR "matrix.csv has ${n_rows} rows, expected 56")
    endif()
    set(cases "")
    foreach(row IN LISTS rows)
      string(REPLACE "," ";" cells "${row}")
      list(GET cells ${i_case} c)
      list(GET cells ${i_candidate} name)
      list(APPEND cases ${c})
      foreach(col cloth_bias cloth_bias_z memory_bytes memory_channels)
        list(GET cells ${i_${col}} ${col}_${c}_${name})
      endforeach()
    endforeach()
    list(REMOVE_DUPLICATES cases)
    foreach(c IN LISTS cases)
      set(zf ${cloth_bias_z_${c}_fine})
      if(NOT (zf LESS 5 AND zf GREATER -5))
        message(FATAL_ERROR "${c}: the fine grid's cloth bias has z = ${zf}: not consistent with 0")
      endif()
      foreach(name exponential-2x local-gamma-2x local-gamma-segment-2x exponential-4x local-gamma-4x
                   local-gamma-segment-4x slab-gamma)
        if(cloth_bias_z_${c}_${name} GREATER 5 AND NOT cloth_bias_${c}_${name} GREATER cloth_bias_${c}_fine)
          message(FATAL_ERROR "${c}: ${name} (cloth bias ${cloth_bias_${c}_${name}}, z ${cloth_bias_z_${c}_${name}}) "
                              "is not more biased than the fine grid (${cloth_bias_${c}_fine})")
        endif()
      endforeach()
      foreach(f 2 4)
        set(e ${memory_bytes_${c}_exponential-${f}x})
        math(EXPR fields "(4 + 3 * 2) * ${e} / 4")  # 4 bytes of C̄ and 3 x 2 of Var C per block
        foreach(name local-gamma-${f}x local-gamma-segment-${f}x)
          if(NOT memory_channels_${c}_${name} EQUAL 4 OR NOT memory_bytes_${c}_${name} EQUAL fields)
            message(FATAL_ERROR "${c}: ${name} holds ${memory_bytes_${c}_${name}} bytes in "
                                "${memory_channels_${c}_${name}} channels, expected 2.5 x ${e}")
          endif()
        endforeach()
        if(NOT memory_channels_${c}_exponential-${f}x EQUAL 1 OR NOT e LESS memory_bytes_${c}_fine)
          message(FATAL_ERROR "${c}: exponential-${f}x holds ${e} bytes (fine ${memory_bytes_${c}_fine})")
        endif()
      endforeach()
      if(NOT memory_bytes_${c}_slab-gamma EQUAL 12 OR NOT memory_channels_${c}_fine EQUAL 1)
        message(FATAL_ERROR "${c}: slab ${memory_bytes_${c}_slab-gamma} bytes, fine ${memory_channels_${c}_fine} channels")
      endif()
    endforeach()
    if(PYTHON)
      execute_process(COMMAND ${PYTHON} ${CMAKE_CURRENT_LIST_DIR}/check_matrix_split.py ${d}/matrix.json exponential
                      RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
      if(NOT rc EQUAL 0)
        message(FATAL_ERROR "bias against scale and components: ${out}${err}")
      endif()
    endif()
    file(READ ${d}/matrix.md md)
    if(NOT md MATCHES "Bias against image scale" OR NOT md MATCHES "\\| plain-back-45deg \\| exponential-4x \\|")
      message(FATAL_ERROR "matrix.md lacks the scale table or the components of exponential-4x")
    endif()
    file(READ ${d}/matrix.json summary)
    string(JSON n_head LENGTH "${summary}" headlines)
    string(JSON text GET "${summary}" headlines 0 text)
    if(NOT n_head EQUAL 2 OR NOT text MATCHES "^plain")
      message(FATAL_ERROR "headlines: ${n_head}, '${text}'")
    endif()

    # --resume: every case from the store, the aggregate files byte for byte.
    set(aggregate matrix.csv matrix.cost.csv matrix.json matrix.md)
    foreach(f IN LISTS aggregate)
      file(COPY_FILE ${d}/${f} ${WORK}/first_${f})
    endforeach()
    execute_process(COMMAND ${WEFT} ${args} --out ${d} --resume RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0 OR NOT out MATCHES "4 of 4 cases resumed")
      message(FATAL_ERROR "resumed run (${rc}) did not take the 4 stored cases: ${out}${err}")
    endif()
    foreach(f IN LISTS aggregate)
      execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/first_${f} ${d}/${f} RESULT_VARIABLE same)
      if(NOT same EQUAL 0)
        message(FATAL_ERROR "${f} differs after --resume")
      endif()
    endforeach()
    # Another spec in the same folder with --resume is refused, not mixed with the stored cases.
    execute_process(COMMAND ${WEFT} ${args} --study-spp 4 --out ${d} --resume RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 1 OR NOT err MATCHES "^weft: error: ")
      message(FATAL_ERROR "--resume with another spec: exit ${rc}, '${err}' (expected exit 1 and one error line)")
    endif()
    return()
  endif()

  if(CASE STREQUAL "same_bytes")
    include(${CMAKE_CURRENT_LIST_DIR}/mpi_common.cmake)
    # Timing-derived entries of matrix.json, besides the keys every MPI comparison skips.
    set(SKIP_KEYS "^(timings|timings_seconds|seconds|.*_seconds|threads|ranks|resumed_units|elapsed|cost_ratio|speedup|speedup_ceiling|error_for_3x|text)$")
    # 2 cases (one cloth, two light set-ups): one per rank under mpirun -n 2.
    set(small render --study --quick --study-factors 2 --study-cloths plain --study-lightings back,front --study-tilts 45
              --seed 3 --study-components exponential)
    set(runs t1)
    execute_process(COMMAND ${WEFT} --quiet --threads 1 ${small} --out ${WORK}/t1
                    RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "matrix failed (${rc}): ${err}")
    endif()
    if(MPIEXEC)
      execute_process(COMMAND ${MPIEXEC} ${MPIFLAGS} -n 2 ${WEFT} --quiet --threads 1 ${small} --out ${WORK}/n2 RESULT_VARIABLE rc ERROR_VARIABLE err)
      if(NOT rc EQUAL 0)
        message(FATAL_ERROR "matrix under mpirun -n 2 failed (${rc}): ${err}")
      endif()
      list(APPEND runs n2)
    endif()
    execute_process(COMMAND ${WEFT} --quiet --threads 2 ${small} --out ${WORK}/t2
                    RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "matrix with 2 threads failed (${rc}): ${err}")
    endif()
    list(APPEND runs t2)
    file(GLOB_RECURSE exrs RELATIVE ${WORK}/t1 ${WORK}/t1/cases/*.exr)
    list(LENGTH exrs n_exr)
    if(n_exr LESS 10)
      message(FATAL_ERROR "expected every case's reference and candidate images, found: ${exrs}")
    endif()
    foreach(run IN LISTS runs)
      if(run STREQUAL "t1")
        continue()
      endif()
      foreach(f matrix.csv ${exrs})
        execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/t1/${f} ${WORK}/${run}/${f} RESULT_VARIABLE same)
        if(NOT same EQUAL 0)
          message(FATAL_ERROR "${f} differs between t1 and ${run}")
        endif()
      endforeach()
      file(READ ${WORK}/t1/matrix.json ja)
      file(READ ${WORK}/${run}/matrix.json jb)
      strip_keys(ja)
      strip_keys(jb)
      string(JSON same EQUAL "${ja}" "${jb}")
      if(NOT same)
        message(FATAL_ERROR "matrix.json (timings stripped) differs between t1 and ${run}")
      endif()
    endforeach()
    message(STATUS "matrix identical for: ${runs}")
    return()
  endif()
  if(CASE STREQUAL "distance")
    # scripts/study_distance: the matrix at 1 and 2 yarns on the same --quick film, tabulated.
    execute_process(COMMAND ${PYTHON} ${SCRIPT} --weft ${WEFT} --out ${WORK}/dist --yarns 1,2 --
                            --quick --study-cloths plain --study-lightings back --study-tilts 45 --study-factors 2 --seed 3
                    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "study_distance failed (${rc}): ${err}")
    endif()
    execute_process(COMMAND ${PYTHON} ${CMAKE_CURRENT_LIST_DIR}/check_study_distance.py ${WORK}/dist 1 2
                    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "study_distance's table: ${out}${err}")
    endif()
    message(STATUS "${out}")
    # Bad options: one line and exit 2 before any run; a missing run: exit 1 and no table.
    foreach(bad "--yarns;0" "--yarns;1,1" "--out;" "--families;bogus;--tabulate-only")
      execute_process(COMMAND ${PYTHON} ${SCRIPT} --weft ${WEFT} --out ${WORK}/dist --yarns 1,2 ${bad}
                      RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
      string(REGEX MATCHALL "\n" lines "${err}")
      list(LENGTH lines nlines)
      if(NOT rc EQUAL 2 OR NOT nlines EQUAL 1 OR NOT err MATCHES "^study_distance: ")
        message(FATAL_ERROR "study_distance ${bad}: exit ${rc}, wanted 2 and one line: ${err}")
      endif()
    endforeach()
    execute_process(COMMAND ${PYTHON} ${SCRIPT} --weft ${WEFT} --out ${WORK}/none --yarns 1 --tabulate-only
                    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 1 OR EXISTS ${WORK}/none/distance.md)
      message(FATAL_ERROR "study_distance --tabulate-only on a missing run: exit ${rc}, wanted 1 and no table")
    endif()
    return()
  endif()
  message(FATAL_ERROR "unknown CASE '${CASE}'")
endif()

set(_matrix_work ${CMAKE_CURRENT_BINARY_DIR}/render_matrix)
add_test(NAME cli.render_study.matrix_quick
         COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> -DCASE=quick -DWORK=${_matrix_work}/quick
                 -DPYTHON=${Python3_EXECUTABLE}
                 -P ${CMAKE_CURRENT_LIST_FILE})
set_tests_properties(cli.render_study.matrix_quick PROPERTIES LABELS "cli;render" TIMEOUT 300)
add_test(NAME cli.render_study.distance_quick
         COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> -DCASE=distance -DWORK=${_matrix_work}/distance
                 -DPYTHON=${Python3_EXECUTABLE} -DSCRIPT=${PROJECT_SOURCE_DIR}/scripts/study_distance
                 -P ${CMAKE_CURRENT_LIST_FILE})
set_tests_properties(cli.render_study.distance_quick PROPERTIES LABELS "cli;render" TIMEOUT 300)
set(_matrix_mpi "")
if(WEFT_MPI AND MPIEXEC_EXECUTABLE)
  execute_process(COMMAND ${MPIEXEC_EXECUTABLE} --version OUTPUT_VARIABLE _matrix_mpi_version ERROR_QUIET)
  set(_matrix_mpi_flags "")
  if(_matrix_mpi_version MATCHES "Open MPI|OpenRTE")
    set(_matrix_mpi_flags "--allow-run-as-root;--oversubscribe;--quiet")
  endif()
  set(_matrix_mpi "-DMPIEXEC=${MPIEXEC_EXECUTABLE}" "-DMPIFLAGS=${_matrix_mpi_flags}")
endif()
add_test(NAME cli.mpi.same_bytes.render_matrix
         COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> -DCASE=same_bytes ${_matrix_mpi}
                 -DWORK=${_matrix_work}/same_bytes -P ${CMAKE_CURRENT_LIST_FILE})
# RUN_SERIAL: an mpirun job beside other tests on 2 cores failed to launch under load (cli_mpi).
set_tests_properties(cli.mpi.same_bytes.render_matrix PROPERTIES LABELS "cli;render;mpi" TIMEOUT 300 RUN_SERIAL TRUE)
