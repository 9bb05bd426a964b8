# dynid from the command line: a twin dataset is resumable (a rerun with the same seed and
# twin skips finished runs; a different twin reruns them), its logs read back through
# preprocessing, and bad input gets a clear error. Run with -DDYNID=<path> -DWORK=<dir>.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

include(${CMAKE_CURRENT_LIST_DIR}/cli_test_helpers.cmake)
function(run expect_code out_var)  # dynid <arguments>
  run_command(${expect_code} out ${DYNID} ${ARGN})
  set(${out_var} "${out}" PARENT_SCOPE)
endfunction()

set(ds ${WORK}/data)
run(0 out twin dataset --robot crane_x7 -o ${ds} --trials 2 --seed 4 --only V01 V02 --jobs 2)
expect("${out}" "4 runs \\(4 new, 0 skipped\\)")
foreach(f V01_t1.csv V01_t2.csv V02_t1.csv V02_t2.csv V01_t1.meta.yaml dataset.yaml)
  if(NOT EXISTS ${ds}/${f})
    message(FATAL_ERROR "missing ${ds}/${f}")
  endif()
endforeach()
file(READ ${ds}/V01_t1.csv first)
run(0 out twin dataset --robot crane_x7 -o ${ds} --trials 2 --seed 4 --only V01 V02)
expect("${out}" "4 runs \\(0 new, 4 skipped\\)")
file(READ ${ds}/V01_t1.csv again)
if(NOT first STREQUAL again)
  message(FATAL_ERROR "a skipped run was rewritten")
endif()
run(0 out twin dataset --robot crane_x7 -o ${ds} --trials 2 --seed 4 --only V01 V02 --without sensor_noise)
expect("${out}" "4 runs \\(4 new, 0 skipped\\)")

run(0 out preprocess --robot crane_x7 ${ds}/V01_t1.csv --interval 40 -o ${WORK}/samples)
expect("${out}" "40 ms: .* samples kept")
if(NOT EXISTS ${WORK}/samples/V01_t1_40ms.csv)
  message(FATAL_ERROR "no samples written")
endif()

run(2 out twin run --robot no_such_robot --trajectory AG02 -o ${WORK}/x)
expect("${out}" "unknown robot 'no_such_robot'")
run(1 out twin run --robot crane_x7 --trajectory AG99 -o ${WORK}/x)
expect("${out}" "AG99")
run(2 out twin run --robot crane_x7 --trajectory AG02 --effects friction -o ${WORK}/x)
expect("${out}" "unknown twin effect 'friction'")
# identify: a folder without a manifest, and a manifest naming a missing log, are named.
file(MAKE_DIRECTORY ${WORK}/empty)
run(1 out identify --robot crane_x7 --data ${WORK}/empty -o ${WORK}/study)
expect("${out}" "empty/dataset.yaml: error: not found")
file(WRITE ${WORK}/empty/dataset.yaml "robot: crane_x7\nruns:\n  - {trajectory: AG02, family: AG, trial: 1, file: AG02_t1.csv}\n")
run(1 out identify --robot crane_x7 --data ${WORK}/empty -o ${WORK}/study)
expect("${out}" "dataset.yaml:3: error: listed file .*AG02_t1.csv does not exist")
# diagnose: the dataset above has V01 and V02 only; unknown effects and missing runs are named.
run(1 out diagnose --robot crane_x7 --data ${ds} -o ${WORK}/diag --only friction)
expect("${out}" "unknown effect 'friction'")
# Without --train the fitting runs are the dataset's non-V families: there are none here.
run(2 out diagnose --robot crane_x7 --data ${ds} -o ${WORK}/diag)
expect("${out}" "dataset.yaml: no fitting run for trial 1 \\(runs: V01 \\(family V, trial 1\\).*name them with --train")
run(2 out diagnose --robot crane_x7 --data ${ds} -o ${WORK}/diag --train AG02 --heldout V02)
expect("${out}" "no run AG02 of trial 1 to fit .*choose others with --train / --heldout")
run(2 out diagnose --robot crane_x7 --data ${ds} -o ${WORK}/diag --train V01 --heldout V02 --apply --variant Upper)
expect("${out}" "--variant 'Upper' must be a lower-case identifier")
# Fitted on V01, judged on V02 (clean twin data): a report, and no effect named.
run(0 out diagnose --robot crane_x7 --data ${ds} -o ${WORK}/diag --train V01 --heldout V02)
expect("${out}" "no missing effect found")
if(NOT EXISTS ${WORK}/diag/diagnosis.md OR NOT EXISTS ${WORK}/diag/figures/heldout_rmse.svg)
  message(FATAL_ERROR "no diagnosis report written")
endif()
# --params: an earlier identification's parameters must be this model's, named with file and line.
file(WRITE ${WORK}/params.yaml "robot: crane_x7\nparameters:\n  - {name: ZZR1, value: 0.01}\n  - {name: XX9, value: 1}\n")
run(1 out diagnose --robot crane_x7 --data ${ds} -o ${WORK}/diag_held --train V01 --heldout V02 --params ${WORK}/params.yaml)
expect("${out}" "params.yaml:4: error: parameter 'XX9' is not one of the identified model's")
file(WRITE ${WORK}/params.yaml "robot: crane_x7\nparameters:\n  - {name: ZZR1, value: 0.01}\n")
run(1 out diagnose --robot crane_x7 --data ${ds} -o ${WORK}/diag_held --train V01 --heldout V02 --params ${WORK}/params.yaml)
expect("${out}" "params.yaml:3: error: parameter '.*' is missing \\(39 expected\\)")
run(2 out diagnose --robot crane_x7 --data ${ds} -o ${WORK}/diag_held --only payload)
expect("${out}" "--only payload needs --params")
if(EXISTS ${WORK}/diag_held)
  message(FATAL_ERROR "a refused --params wrote a report")
endif()
# A dataset made with --config keeps the overrides, so its truth (the hidden effects) travels
# with it.
file(WRITE ${WORK}/hidden.yaml "effects:\n  torque_offset: {enabled: true, torque: [0, 0, 0, 0, 0.02, 0, 0, 0]}\n")
run(0 out twin dataset --robot crane_x7 -o ${WORK}/hidden --seed 4 --only V01 --config ${WORK}/hidden.yaml)
file(READ ${WORK}/hidden/dataset.yaml manifest)
expect("${manifest}" "twin_overrides: twin_overrides.yaml")
file(READ ${WORK}/hidden/twin_overrides.yaml kept)
expect("${kept}" "torque: \\[0, 0, 0, 0, 0.02")
# Models by name: an unknown one is named with the robot's compiled models.
run(2 out diagnose --robot crane_x7 --data ${ds} -o ${WORK}/diag --model nope)
expect("${out}" "no compiled model 'nope' \\(it has: full, reduced, reduced_diagnosed")
run(2 out identify --robot crane_x7 --data ${ds} -o ${WORK}/study --model nope)
expect("${out}" "no compiled model 'nope'")
# compare: a folder that is not a study, and a study against itself (no figure trajectory).
run(1 out compare --before ${WORK}/diag --after ${WORK}/diag -o ${WORK}/gap)
expect("${out}" "diag/validation.yaml: error: not found")
file(WRITE ${WORK}/bad.csv "time,q1\n0,1\n")
run(1 out preprocess ${WORK}/bad.csv)
expect("${out}" "bad")
# control: one second of AG02 on the virtual bus (emulated servos driving the twin), then a
# preprocessable log; a missing port is named.
run(0 out control --robot crane_x7 --virtual --trajectory AG02 --seconds 1 -o ${WORK}/control/run.csv)
expect("${out}" "completed; torque off confirmed")
expect("${out}" "overruns")
run(0 out preprocess --robot crane_x7 ${WORK}/control/run.csv --interval 40 -o ${WORK}/control/samples)
# A log the controller wrote (its time starts after the approach and pre-roll, at t > 0; its
# reference columns are the controller's) through identify with CLIE: the closed loop replays
# the log's own references, from its first stamp.
# V02 whole (18 s): every axis moves, so every parameter is excited.
run(0 out control --robot crane_x7 --virtual --trajectory V02 -o ${WORK}/control/V02.csv)
file(WRITE ${WORK}/control/dataset.yaml "format: symoro-dataset 1\nrobot: crane_x7\nruns:\n  - {trajectory: V02, family: AG, trial: 1, file: V02.csv}\n")
run(0 out identify --robot crane_x7 --data ${WORK}/control -o ${WORK}/control/study --interval 20)
expect("${out}" "CLIE: 1 runs\n")
expect("${out}" "representative: V02@20ms")
# export: this one-run study's accepted vector has no physically consistent standard set (it
# is PD over the audit box, which is necessary, not sufficient): no URDF, the nearest consistent
# vector's distance and the torque it costs on the fitting run; --nearest writes that one, said
# in the URDF.
run(1 out export --robot crane_x7 --study ${WORK}/control/study --urdf ${WORK}/control/crane.urdf --data ${WORK}/control)
expect("${out}" "no URDF written: no consistent standard set maps onto phi")
expect("${out}" "on V02@20ms \\(trial 1, [0-9]+ samples\\), the nearest consistent vector \\(nearest in this run's predicted torque\\) changes the predicted torque by RMS [0-9.e-]+ N m")
if(EXISTS ${WORK}/control/crane.urdf)
  message(FATAL_ERROR "a refused export wrote its URDF")
endif()
run(0 out export --robot crane_x7 --study ${WORK}/control/study --urdf ${WORK}/control/crane.urdf --data ${WORK}/control --nearest)
file(READ ${WORK}/control/crane.urdf urdf)
expect("${urdf}" "WARNING: no consistent set reproduces the accepted base parameters")
expect("${urdf}" "<robot name=\"crane_x7\"")
# The same run identified on the physical path: its final vector (the paper's CLIE) has no
# consistent set either, so the rescue projects it onto the vectors that have one; the export then
# reproduces the accepted vector itself (no --nearest, no warning).
run(2 out identify --robot crane_x7 --data ${WORK}/control -o ${WORK}/control/study-physical --interval 20 --physical-start)
expect("${out}" "--physical-start needs --consistency physical")
run(0 out identify --robot crane_x7 --data ${WORK}/control -o ${WORK}/control/study-physical --interval 20
    --consistency physical)
expect("${out}" "representative: V02@20ms \\([^\n]*\\); rescued onto the consistent set; final audit lambda_min [0-9.e+-]+ -> accepted")
expect("${out}" "physical consistency of the accepted vector: consistent")
file(READ ${WORK}/control/study-physical/report/parameters.yaml params)
expect("${params}" "consistency: \"physical\"\nphysically_consistent: true")
run(0 out export --robot crane_x7 --study ${WORK}/control/study-physical --urdf ${WORK}/control/crane-physical.urdf)
expect("${out}" "max \\|B s - phi\\| = [0-9.e-]+")
file(READ ${WORK}/control/crane-physical.urdf urdf)
if(urdf MATCHES "WARNING")
  message(FATAL_ERROR "the physical study's export warns:\n${urdf}")
endif()
# A log is never overwritten: refused, or written under a new name.
run(2 out control --robot crane_x7 --virtual --trajectory AG02 --seconds 1 -o ${WORK}/control/run.csv)
expect("${out}" "control/run.csv exists: a run never overwrites a log")
run(0 out control --robot crane_x7 --virtual --trajectory AG02 --seconds 1 -o ${WORK}/control/run.csv --if-exists new-name)
expect("${out}" "control/run-1.csv: [0-9]+ rows")
# Parameters whose identification was not accepted drive the arm only when the user says so.
file(READ ${WORK}/control/study/report/parameters.yaml params)
string(REPLACE "accepted: true" "accepted: false" params "${params}")
file(WRITE ${WORK}/control/unaccepted.yaml "${params}")
run(2 out control --robot crane_x7 --virtual --trajectory AG02 --seconds 1 -o ${WORK}/control/ff.csv --params ${WORK}/control/unaccepted.yaml)
expect("${out}" "unaccepted.yaml: the identification was not accepted")
run(0 out control --robot crane_x7 --virtual --trajectory AG02 --seconds 1 -o ${WORK}/control/ff.csv --params ${WORK}/control/unaccepted.yaml --unaccepted-params)
file(READ ${WORK}/control/ff.meta.yaml sidecar)
expect("${sidecar}" "PARAMETERS NOT ACCEPTED")
run(2 out control --robot crane_x7 --port ${WORK}/no_such_tty --seconds 1 -o ${WORK}/control/real2.csv --watchdog 500)
expect("${out}" "--watchdog 500: at most 50 cycles on a real port")
run(2 out control --robot crane_x7 --port ${WORK}/no_such_tty --seconds 1 -o ${WORK}/control/real2.csv --ideal)
expect("${out}" "--config and --ideal change the emulated arm of --virtual only")
run(1 out control --robot crane_x7 --port ${WORK}/no_such_tty --seconds 1 -o ${WORK}/control/real.csv)
expect("${out}" "no_such_tty")
file(REMOVE_RECURSE ${WORK})
