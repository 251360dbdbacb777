# `weft render --study` (docs/render.md §6c): accuracy vs time in images.
# Included by tests/cli/CMakeLists.txt (adds the tests) and run as a script for one case:
#   cmake -DWEFT=... -DCHECK=... -DPROBE=... -DWORK=... -DCASE=quick|same_bytes [-DMPIEXEC=... -DMPIFLAGS=...]
#         -P cli_render_study.cmake
#
# quick: the default cloth at 48 px, factors 2 and 4, 8 spp per candidate, a 256 spp reference.
#   Every file exists; the CSV has one row per candidate (fine, exponential, local-gamma and
#   shadow-corrected at 2x and 4x, the slab); the bias estimates are statistical statements with
#   standard errors:
#   the fine grid (the reference's own model) is consistent with no bias (bias² within 5
#   standard errors of 0) and a smaller bias than every candidate whose bias is detectable
#   (z > 5), and the slab (one homogeneous gamma law for a woven cloth) is biased beyond 5
#   standard errors — a study that cannot tell these apart fails; the reference and a candidate show a cloth (weft_cloth_image_check); the contact sheet
#   has its 3 x 5 tiles.
# same_bytes: fixed spp gives the same images with --threads 1 and 2 (and under mpirun -n 2
#   when MPI is there), and each candidate's scene file renders its image again byte for byte.

if(CMAKE_SCRIPT_MODE_FILE)
  file(REMOVE_RECURSE ${WORK})
  file(MAKE_DIRECTORY ${WORK})
  if(CASE STREQUAL "quick")
    execute_process(COMMAND ${WEFT} render --study --lighting key-and-back --quick --study-spp 8 --study-factors 2,4 --reference-spp 256
                            --out ${WORK}/run RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "study failed (${rc}): ${err}")
    endif()
    message(STATUS "${out}")
    set(candidates fine exponential-2x local-gamma-2x shadow-corrected-2x shadow-directional-2x exponential-4x local-gamma-4x
        shadow-corrected-4x shadow-directional-4x slab-gamma)
    set(d ${WORK}/run)
    foreach(f default_cloth.exr default_cloth.png default_cloth.study.csv default_cloth.study.curves.csv
              default_cloth.study.json default_cloth.study.contact.png default_cloth.study/reference.json
              default_cloth.study/grid_2x.vdb default_cloth.study/fields_4x.vdb)
      if(NOT EXISTS ${d}/${f})
        message(FATAL_ERROR "missing output ${f}")
      endif()
    endforeach()
    foreach(c IN LISTS candidates)
      foreach(ext exr json)
        if(NOT EXISTS ${d}/default_cloth.study/${c}.${ext})
          message(FATAL_ERROR "missing candidate file ${c}.${ext}")
        endif()
      endforeach()
    endforeach()
    # CSV: header, then one row per candidate in order; bias² and its standard error by name.
    file(STRINGS ${d}/default_cloth.study.csv rows)
    list(GET rows 0 header)
    string(REPLACE "," ";" columns "${header}")
    list(FIND columns candidate i_name)
    list(FIND columns bias i_bias)
    list(FIND columns bias_sq i_bsq)
    list(FIND columns bias_sq_stderr i_bse)
    list(FIND columns rmse i_rmse)
    list(FIND columns spp i_spp)
    if(i_name LESS 0 OR i_bias LESS 0 OR i_bsq LESS 0 OR i_bse LESS 0 OR i_rmse LESS 0 OR i_spp LESS 0)
      message(FATAL_ERROR "CSV header lacks a column: ${header}")
    endif()
    list(REMOVE_AT rows 0)
    set(names "")
    foreach(row IN LISTS rows)
      string(REPLACE "," ";" cells "${row}")
      list(GET cells ${i_name} name)
      list(GET cells ${i_bias} bias_${name})
      list(GET cells ${i_bsq} bsq_${name})
      list(GET cells ${i_bse} bse_${name})
      list(GET cells ${i_rmse} rmse)
      list(GET cells ${i_spp} spp)
      list(APPEND names ${name})
      if(NOT spp EQUAL 8 OR NOT rmse GREATER 0)
        message(FATAL_ERROR "bad CSV row '${row}' (expected 8 spp and RMSE > 0)")
      endif()
    endforeach()
    if(NOT names STREQUAL "${candidates}")
      message(FATAL_ERROR "CSV candidates '${names}', expected '${candidates}'")
    endif()
    # Fine grid: bias² within 5 standard errors of 0 (z = bias²/se, from the CSV) and the
    # smallest bias of all; the slab: bias² beyond 5 standard errors.
    list(FIND columns bias_z i_z)
    foreach(row IN LISTS rows)
      string(REPLACE "," ";" cells "${row}")
      list(GET cells ${i_name} name)
      list(GET cells ${i_z} z_${name})
    endforeach()
    if(NOT (z_fine LESS 5 AND z_fine GREATER -5))
      message(FATAL_ERROR "fine grid bias² is ${bsq_fine} +- ${bse_fine} (z ${z_fine}): not consistent with 0")
    endif()
    if(NOT z_slab-gamma GREATER 5)
      message(FATAL_ERROR "slab bias² is ${bsq_slab-gamma} +- ${bse_slab-gamma} (z ${z_slab-gamma}): not detected")
    endif()
    # Every candidate with a detectable bias (z > 5) has a larger one than the fine grid's
    # estimate (candidates with undetectable bias are indistinguishable from it, either order).
    foreach(c IN LISTS candidates)
      if(z_${c} GREATER 5 AND NOT bias_${c} GREATER bias_fine)
        message(FATAL_ERROR "candidate ${c} (bias ${bias_${c}}, z ${z_${c}}) is not more biased than the fine grid "
                            "(${bias_fine})")
      endif()
    endforeach()
    file(READ ${d}/default_cloth.study.json summary)
    string(JSON headline GET "${summary}" headline)
    # (c) is chosen against the ground truth: labelled so, and under the former key too.
    string(JSON best GET "${summary}" best_by_ground_truth model)
    string(JSON note GET "${summary}" best_by_ground_truth note)
    string(JSON labelled GET "${summary}" best_by_ground_truth uses_ground_truth)
    string(JSON former GET "${summary}" best_predictive)
    string(JSON current GET "${summary}" best_by_ground_truth)
    if(headline STREQUAL "" OR best STREQUAL "" OR NOT note MATCHES "^\\(c\\) is ${best}" OR NOT labelled
       OR NOT former STREQUAL current)
      message(FATAL_ERROR "headline '${headline}', best by ground truth '${best}' (uses_ground_truth ${labelled}), "
                          "note '${note}'")
    endif()
    foreach(img default_cloth.exr default_cloth.study/fine.exr default_cloth.study/local-gamma-4x.exr)
      execute_process(COMMAND ${CHECK} ${d}/${img} RESULT_VARIABLE crc OUTPUT_VARIABLE cout ERROR_VARIABLE cerr)
      if(NOT crc EQUAL 0)
        message(FATAL_ERROR "${img} shows no cloth: ${cout}${cerr}")
      endif()
    endforeach()
    # The sheet's layout: 3 columns (reference or fine, then factors 2 and 4) and 5 rows (images,
    # error maps, images, error maps, the slab), tiles enlarged to >= 192 px (contact_sheet.h).
    execute_process(COMMAND ${PROBE} ${d}/default_cloth.study.contact.png 0,0,0 --min-pixels 0
                    OUTPUT_VARIABLE pout)
    string(REGEX MATCH "width ([0-9]+) height ([0-9]+)" m "${pout}")
    if(NOT m OR CMAKE_MATCH_1 LESS 576 OR CMAKE_MATCH_2 LESS 720)
      message(FATAL_ERROR "contact sheet is not 3 x 5 tiles of >= 192 px: ${pout}")
    endif()
    return()
  endif()

  if(CASE STREQUAL "same_bytes")
    set(args render --study --lighting key-and-back --quick --study-spp 2 --study-factors 2 --reference-spp 8 --seed 5)
    set(runs t1 t2)
    execute_process(COMMAND ${WEFT} --quiet --threads 1 ${args} --out ${WORK}/t1 RESULT_VARIABLE rc1 ERROR_VARIABLE e1)
    execute_process(COMMAND ${WEFT} --quiet --threads 2 ${args} --out ${WORK}/t2 RESULT_VARIABLE rc2 ERROR_VARIABLE e2)
    if(NOT rc1 EQUAL 0 OR NOT rc2 EQUAL 0)
      message(FATAL_ERROR "study runs failed: ${e1} ${e2}")
    endif()
    if(MPIEXEC)
      execute_process(COMMAND ${MPIEXEC} ${MPIFLAGS} -n 2 ${WEFT} --quiet --threads 1 ${args} --out ${WORK}/n2
                      RESULT_VARIABLE rc3 ERROR_VARIABLE e3)
      if(NOT rc3 EQUAL 0)
        message(FATAL_ERROR "study under mpirun -n 2 failed: ${e3}")
      endif()
      list(APPEND runs n2)
    endif()
    file(GLOB exrs RELATIVE ${WORK}/t1 ${WORK}/t1/*.exr ${WORK}/t1/*/*.exr)
    list(LENGTH exrs n_exr)
    if(n_exr LESS 5)
      message(FATAL_ERROR "expected the reference and 4 candidate images, found: ${exrs}")
    endif()
    foreach(run IN LISTS runs)
      foreach(f IN LISTS exrs)
        execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/t1/${f} ${WORK}/${run}/${f} RESULT_VARIABLE same)
        if(NOT same EQUAL 0)
          message(FATAL_ERROR "${f} differs between --threads 1 and ${run}")
        endif()
      endforeach()
    endforeach()
    # The scene file of a candidate renders its image again (spp and seed are in it).
    foreach(c fine local-gamma-2x slab-gamma)
      execute_process(COMMAND ${WEFT} --quiet render ${WORK}/t1/default_cloth.study/${c}.json -o ${WORK}/again_${c}.exr
                      RESULT_VARIABLE rc ERROR_VARIABLE err)
      execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/again_${c}.exr
                              ${WORK}/t1/default_cloth.study/${c}.exr RESULT_VARIABLE same)
      if(NOT rc EQUAL 0 OR NOT same EQUAL 0)
        message(FATAL_ERROR "${c}.json does not render ${c}.exr again (${rc}): ${err}")
      endif()
    endforeach()
    message(STATUS "study images identical for: ${runs}; ${exrs}")
    return()
  endif()
  message(FATAL_ERROR "unknown CASE '${CASE}'")
endif()

set(_study_work ${CMAKE_CURRENT_BINARY_DIR}/render_study)
add_test(NAME cli.render_study.quick
         COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> -DCHECK=$<TARGET_FILE:weft_cloth_image_check>
                 -DPROBE=$<TARGET_FILE:png_probe> -DCASE=quick -DWORK=${_study_work}/quick -P ${CMAKE_CURRENT_LIST_FILE})
set_tests_properties(cli.render_study.quick PROPERTIES LABELS "cli;render" TIMEOUT 300)
set(_study_mpi "")
if(WEFT_MPI AND MPIEXEC_EXECUTABLE)
  execute_process(COMMAND ${MPIEXEC_EXECUTABLE} --version OUTPUT_VARIABLE _study_mpi_version ERROR_QUIET)
  set(_study_mpi_flags "")
  if(_study_mpi_version MATCHES "Open MPI|OpenRTE")
    set(_study_mpi_flags "--allow-run-as-root;--oversubscribe;--quiet")
  endif()
  set(_study_mpi "-DMPIEXEC=${MPIEXEC_EXECUTABLE}" "-DMPIFLAGS=${_study_mpi_flags}")
endif()
add_test(NAME cli.render_study.same_bytes
         COMMAND ${CMAKE_COMMAND} -DWEFT=$<TARGET_FILE:weft> -DCASE=same_bytes ${_study_mpi}
                 -DWORK=${_study_work}/same_bytes -P ${CMAKE_CURRENT_LIST_FILE})
# RUN_SERIAL: an mpirun job beside other tests on 2 cores failed to launch under load (cli_mpi).
set_tests_properties(cli.render_study.same_bytes PROPERTIES LABELS "cli;render;mpi" TIMEOUT 300 RUN_SERIAL TRUE)
