# The README's "Your robot, your logs" commands on robots with only their robots/ folder (no
# twin.yaml, trajectories.yaml or controller.yaml): a controller's CSV export (write_export:
# degrees, milliseconds, its own column names, stale rows, Coulomb friction and an offset on the
# last joint) of the RX-90 and the Stanford RRP arm (a prismatic joint, left in m) is imported
# with a 70/30 split, identified with the model without Coulomb friction (`rigid`) and the full
# one (CLIE skipped and said, open-loop validation on the held-out part), diagnosed (names the
# friction and the offset) and compared; the full model's study is exported as a URDF (dynid export
# --urdf; no twin.yaml, so --prior is required) and, when -DCHECK_URDF names urdfdom's check_urdf,
# read back with it. Then a robot from its URDF alone (robots/ur5), below. Run with -DDYNID,
# -DWRITE_EXPORT, -DWORK, -DURDF_DIR [-DCHECK_URDF].
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

include(${CMAKE_CURRENT_LIST_DIR}/cli_test_helpers.cmake)

foreach(robot rx90 stanford_rrp)
  set(w ${WORK}/${robot})
  file(MAKE_DIRECTORY ${w})
  set(before rigid)
  set(after full)
  execute_process(COMMAND ${WRITE_EXPORT} ${robot} ${w}/export.csv 60 5 RESULT_VARIABLE code)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "write_export ${robot} failed")
  endif()
  run(0 out import --robot ${robot} -o ${w}/data ${w}/export.csv --name arm --time stamp_ms --time-unit ms
      --q "{name}_pos" --qd "{name}_vel" --tau "{name}_eff" --angle deg --split 0.7)
  expect("${out}" "stale")
  file(READ ${w}/data/dataset.yaml manifest)
  expect("${manifest}" "trajectory: \"?arm_heldout\"?, family: \"?V\"?")
  # Two imports into one folder at once: one imports, the other is refused (both used to exit 0
  # and one input was lost).
  if(robot STREQUAL "rx90")
    find_program(BASH bash)
    set(args import --robot ${robot} -o '${w}/race' '${w}/export.csv' --time stamp_ms --time-unit ms --q '{name}_pos'
        --qd '{name}_vel' --tau '{name}_eff' --angle deg)
    string(REPLACE ";" " " args "${args}")
    run_command(0 out ${BASH} -c "('${DYNID}' ${args} --name one > '${w}/race-a.out' 2>&1 && echo RESULT-ok >> '${w}/race-a.out' || echo RESULT-refused >> '${w}/race-a.out') & ('${DYNID}' ${args} --name two > '${w}/race-b.out' 2>&1 && echo RESULT-ok >> '${w}/race-b.out' || echo RESULT-refused >> '${w}/race-b.out') & wait")
    file(READ ${w}/race-a.out a)
    file(READ ${w}/race-b.out b)
    string(REGEX MATCHALL "RESULT-ok" oks "${a}${b}")
    list(LENGTH oks n)
    if(NOT n EQUAL 1)
      message(FATAL_ERROR "two imports into one folder: ${n} succeeded:\n${a}\n${b}")
    endif()
    expect("${a}${b}" "(in use by pid [0-9]+ \\(dynid import\\)|exists already; the importer never replaces a file)")
  endif()
  # Importing again never replaces what is there.
  run(1 out import --robot ${robot} -o ${w}/data ${w}/export.csv --name arm --time stamp_ms --time-unit ms
      --q "{name}_pos" --qd "{name}_vel" --tau "{name}_eff" --angle deg --split 0.7)
  # Degrees declared as radians: positions far beyond the joint limits are refused with the
  # evidence and the override, which imports them as they are; a split leaving one sample too.
  set(deg_as_rad --robot ${robot} ${w}/export.csv --name arm --time stamp_ms --time-unit ms
      --q "{name}_pos" --qd "{name}_vel" --tau "{name}_eff" --angle rad)
  run(1 out import -o ${w}/deg-as-rad ${deg_as_rad})
  expect("${out}" "export.csv:[0-9]+: error: joint [0-9]+ '[a-z0-9_]+' is at -?[0-9.e+-]+ rad, far outside its limits")
  expect("${out}" "import with --allow-implausible")
  run(0 out import -o ${w}/deg-as-rad ${deg_as_rad} --allow-implausible)
  # Torques 1000 times too large (a scale the wrong way round, mN m taken for N m) are refused at
  # their line, beyond 5 times the joint's effort limit, with the override (they imported, rc 0).
  if(robot STREQUAL "rx90")
    set(milli --robot ${robot} ${w}/export.csv --name arm --time stamp_ms --time-unit ms --q "{name}_pos" --qd "{name}_vel"
        --tau "{name}_eff" --angle deg --torque-scale 1000)
    run(1 out import -o ${w}/milli ${milli})
    expect("${out}" "export.csv:[0-9]+: error: joint [0-9]+ '[a-z0-9_]+' has a torque of -?[0-9.e+-]+ N m, beyond 5 times its effort limit")
    expect("${out}" "--torque-scale")
    run(0 out import -o ${w}/milli ${milli} --allow-implausible)
  endif()
  run(1 out import -o ${w}/split-1e-9 --robot ${robot} ${w}/export.csv --name arm --time stamp_ms --time-unit ms
      --q "{name}_pos" --qd "{name}_vel" --tau "{name}_eff" --angle deg --split 1e-9)
  expect("${out}" "split 1e-09 at [0-9.e+-]+ s leaves 1 of the [0-9]+ samples in the fitting part")
  # A dataset of another robot is refused, naming the manifest.
  if(robot STREQUAL "rx90")
    run(1 out identify --robot stanford_rrp --data ${w}/data -o ${w}/wrong)
    expect("${out}" "dataset.yaml:[0-9]+: error: the dataset was made for robot 'rx90', not 'stanford_rrp'")
  endif()

  foreach(model ${before} ${after})
    run(0 out identify --robot ${robot} --model ${model} --data ${w}/data -o ${w}/study-${model} --interval 10)
    expect("${out}" "CLIE: 0 runs; skipped in 1 \\(not run: no controller description")
    expect("${out}" "validation arm_heldout at 10 ms, open-loop")
    expect("${out}" "validation arm_heldout against the raw torque, open loop: RMSE [0-9.]+ / [0-9.]+ N m")
    expect("${out}" "accepted")
    if(NOT EXISTS ${w}/study-${model}/report/report.md OR NOT EXISTS ${w}/study-${model}/validation.yaml)
      message(FATAL_ERROR "${robot} ${model}: no report or validation written")
    endif()
    file(READ ${w}/study-${model}/report/report.md report)
    expect("${report}" "CLIE: 0 runs; skipped")
  endforeach()

  # --logged-velocity fits on the log's own velocity column. Here the export's velocity went
  # through a 5 Hz first-order filter (a controller's causal estimate, late by 32 ms), which the
  # study's zero-phase derivative of q is not: the held-out error against the raw torque must be
  # at least 1.5 times the study's own (in 1e-4 N m: the report prints 4 decimals).
  if(robot STREQUAL "rx90")
    execute_process(COMMAND ${WRITE_EXPORT} ${robot} ${w}/lagged.csv 60 5 5 RESULT_VARIABLE code)
    if(NOT code EQUAL 0)
      message(FATAL_ERROR "write_export ${robot} (lagged velocity) failed")
    endif()
    run(0 out import --robot ${robot} -o ${w}/lagged ${w}/lagged.csv --name arm --time stamp_ms --time-unit ms
        --q "{name}_pos" --qd "{name}_vel" --tau "{name}_eff" --angle deg --split 0.7)
    set(rmse)
    foreach(flag "" --logged-velocity)
      run(0 out identify --robot ${robot} --model ${before} --data ${w}/lagged -o ${w}/lagged/study-${rmse} --interval 10 ${flag})
      string(REGEX MATCH "against the raw torque, open loop: RMSE [0-9.]+ / ([0-9]+)\\.([0-9][0-9][0-9][0-9]) N m" m "${out}")
      if(NOT m)
        message(FATAL_ERROR "no raw-torque RMSE in:\n${out}")
      endif()
      math(EXPR e4 "${CMAKE_MATCH_1} * 10000 + 1${CMAKE_MATCH_2} - 10000")
      list(APPEND rmse ${e4})
    endforeach()
    list(GET rmse 0 own)
    list(GET rmse 1 logged)
    math(EXPR bound "${own} * 3 / 2")
    message(STATUS "--logged-velocity: held-out ${logged}e-4 N m against the study's ${own}e-4 N m")
    if(NOT logged GREATER bound)
      message(FATAL_ERROR "--logged-velocity: held-out ${logged}e-4 N m, not above 1.5 x the study's ${own}e-4 N m")
    endif()
  endif()

  # The fitting and held-out runs come from the dataset's split; no twin: no backlash stage.
  run(0 out diagnose --robot ${robot} --model ${before} --data ${w}/data -o ${w}/diagnosis)
  expect("${out}" "effect: Coulomb friction \\(velocity spread [0-9.]+ rad/s\\), joint 1")
  expect("${out}" "effect: constant torque offset, joint")
  expect("${out}" "backlash stage: Not run: the stage simulates the robot's digital twin")
  expect("${out}" "held-out rms residual against the raw torque: [0-9.]+ -> [0-9.]+ N m")
  file(READ ${w}/diagnosis/diagnosis.md diagnosis)
  expect("${diagnosis}" "Fitted on arm; judged on the held-out arm_heldout")

  run(0 out compare --robot ${robot} --before ${w}/study-${before} --after ${w}/study-${after} -o ${w}/gap)
  file(READ ${w}/gap/gap.md gap)
  expect("${gap}" "\\| arm_heldout \\| open-loop \\|")
  expect("${gap}" "Against the raw measured torque, open loop at the logs' own rate")

  # URDF export: a robot without twin.yaml has no prior to take, so it must be given.
  run(2 out export --robot ${robot} --study ${w}/study-${after} --urdf ${w}/urdf/${robot}.urdf)
  expect("${out}" "has no twin.yaml to take a prior from: give --prior")
  run(2 out export --robot ${robot} --model ${before} --study ${w}/study-${after} --urdf ${w}/urdf/${robot}.urdf)
  expect("${out}" "holds the parameters of model full")
  run(0 out export --robot ${robot} --study ${w}/study-${after} --urdf ${w}/urdf/${robot}.urdf --prior zero --nearest)
  expect("${out}" "urdf: .*${robot}.urdf")
  # The rotor inertia the URDF cannot hold is said, with where a simulator takes it from.
  expect("${out}" "rotor inertia has no URDF field: .*${robot}.standard.yaml \\(MuJoCo: each joint's armature; dynid export --mjcf writes it there\\): IA[0-9]")
  foreach(f ${robot}.urdf ${robot}.standard.yaml ${robot}.standard.csv)
    if(NOT EXISTS ${w}/urdf/${f})
      message(FATAL_ERROR "dynid export wrote no ${f}")
    endif()
  endforeach()
  file(READ ${w}/urdf/${robot}.urdf urdf)
  expect("${urdf}" "modified Denavit-Hartenberg frame")
  expect("${urdf}" "<robot name=\"${robot}\">")
  expect("${urdf}" "<dynamics damping=")
  # The export's standard parameters are read back as a prior.
  run(0 out export --robot ${robot} --study ${w}/study-${after} --urdf ${w}/urdf/again.urdf
      --prior ${w}/urdf/${robot}.standard.yaml --nearest)
  if(CHECK_URDF)
    execute_process(COMMAND ${CHECK_URDF} ${w}/urdf/${robot}.urdf RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT code EQUAL 0)
      message(FATAL_ERROR "check_urdf ${w}/urdf/${robot}.urdf: exit ${code}\n${out}\n${err}")
    endif()
    expect("${out}" "Successfully Parsed XML")
  endif()

  # The physical path: the accepted vector has a consistent set of link inertials, so the export
  # reproduces it without --nearest and without a warning.
  run(0 out identify --robot ${robot} --model ${after} --data ${w}/data -o ${w}/study-physical --interval 10
      --consistency physical)
  expect("${out}" "physical consistency of the accepted vector: consistent")
  file(READ ${w}/study-physical/report/parameters.yaml params)
  expect("${params}" "physically_consistent: true")
  run(0 out export --robot ${robot} --study ${w}/study-physical --urdf ${w}/urdf/physical.urdf --prior zero)
  expect("${out}" "consistent standard parameters: consistent")
  file(READ ${w}/urdf/physical.urdf urdf)
  if(urdf MATCHES "WARNING")
    message(FATAL_ERROR "the physical study's export warns:\n${urdf}")
  endif()
endforeach()

# A robot from its URDF alone: robots/ur5 is what `symoroc model tests/urdf/ur5_robot.urdf` wrote
# (plus a `rigid` variant). Its controller's export is synthesized from the URDF's own inertials
# with what the URDF lacks: Coulomb friction and an offset on the last joint. The nominal model's
# torque on it (dynid predict), the identification, the diagnosis (names what the URDF lacked),
# and the identified inertials written into the user's own URDF (dynid export --into): only its
# <inertial> and <dynamics> change.
set(w ${WORK}/ur5)
file(MAKE_DIRECTORY ${w})
execute_process(COMMAND ${WRITE_EXPORT} ur5 ${w}/export.csv 60 5 RESULT_VARIABLE code)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "write_export ur5 failed")
endif()
run(0 out import --robot ur5 -o ${w}/data ${w}/export.csv --name arm --time stamp_ms --time-unit ms
    --q "{name}_pos" --qd "{name}_vel" --tau "{name}_eff" --angle deg --split 0.7)
run(0 out predict --robot ur5 --params nominal ${w}/data -o ${w}/nominal)
expect("${out}" "ur5 model full with the nominal parameters, at 10 ms")
expect("${out}" "raw: RMSE against the raw torque")
expect("${out}" "arm_heldout")
foreach(f arm arm_heldout)
  if(NOT EXISTS ${w}/nominal/${f}.predicted.csv)
    message(FATAL_ERROR "dynid predict wrote no ${f}.predicted.csv")
  endif()
endforeach()
file(STRINGS ${w}/nominal/arm.predicted.csv header LIMIT_COUNT 1)
expect("${header}" "tau_model_wrist_3_joint")
run(2 out predict --robot ur5 --params nominal ${w}/data -o ${w}/nominal)
expect("${out}" "exists: dynid predict does not overwrite it")
run(0 out identify --robot ur5 --model rigid --data ${w}/data -o ${w}/study-rigid --interval 10)
expect("${out}" "accepted")
run(0 out diagnose --robot ur5 --model rigid --data ${w}/data -o ${w}/diagnosis)
expect("${out}" "effect: Coulomb friction \\(velocity spread [0-9.]+ rad/s\\), joint [12]")
expect("${out}" "effect: constant torque offset, joint 6")
run(0 out identify --robot ur5 --data ${w}/data -o ${w}/study-physical --interval 10 --consistency physical)
expect("${out}" "physical consistency of the accepted vector: consistent")
run(0 out predict --robot ur5 --params ${w}/study-physical/report/parameters.yaml ${w}/data -o ${w}/identified)
expect("${out}" "ur5 model full with .*parameters.yaml")
run(0 out export --robot ur5 --study ${w}/study-physical --urdf ${w}/ur5_identified.urdf --into ${URDF_DIR}/ur5_robot.urdf)
expect("${out}" "nominal: the URDF's inertials")
expect("${out}" "6 chain links' <inertial> and their joints' <dynamics> written into")
file(READ ${w}/ur5_identified.urdf written)
expect("${written}" "package://example-robot-data/robots/ur_description/meshes/ur5/visual/base.dae")
# Into a URDF whose geometry differs from the one the model came from (the elbow 1 cm higher): the
# inertials would be another arm's; refused, naming the joint (it used to be written, rc 0).
file(READ ${URDF_DIR}/ur5_robot.urdf ur5_text)
string(REPLACE "<origin rpy=\"0.0 0.0 0.0\" xyz=\"0.0 -0.1197 0.425\"/>" "<origin rpy=\"0.0 0.0 0.0\" xyz=\"0.0 -0.1197 0.435\"/>"
       moved "${ur5_text}")
if(moved STREQUAL ur5_text)
  message(FATAL_ERROR "the UR5 URDF's elbow origin was not found to move")
endif()
file(WRITE ${w}/ur5_moved.urdf "${moved}")
run(2 out export --robot ur5 --study ${w}/study-physical --urdf ${w}/ur5_moved_identified.urdf --into ${w}/ur5_moved.urdf)
expect("${out}" "ur5_moved.urdf: joint 'elbow_joint' is not the model's joint 3: its axis is 0 deg from the model's and 10 mm off it")
if(EXISTS ${w}/ur5_moved_identified.urdf)
  message(FATAL_ERROR "an export into another arm's URDF was written")
endif()
expect("${written}" "<dynamics damping=")
if(CHECK_URDF)
  execute_process(COMMAND ${CHECK_URDF} ${w}/ur5_identified.urdf RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "check_urdf ${w}/ur5_identified.urdf: exit ${code}\n${out}\n${err}")
  endif()
endif()
file(REMOVE_RECURSE ${WORK})
