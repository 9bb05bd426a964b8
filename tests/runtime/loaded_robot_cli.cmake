# A robot folder dynid was never built with, from its URDF alone (symoroc model), through the
# commands that run on a robot library: dynid builds the folder's library into a fresh robot
# cache on first use, imports a controller's CSV export of the UR5 (write_export: synthesized
# from robots/ur5's generated model with Coulomb friction and an offset), identifies it on the
# physical path, predicts with the result, detects a contact with its momentum observer, exports
# it as a URDF and diagnoses its gap; then the
# same through the compiled robots/ur5: the studies' parameters and validation, the predictions,
# the URDFs and the diagnoses are the same numbers, digit for digit (one generated model, two ways
# to call it). A second study reuses the cached library (no build line). Then the twin, the
# trajectories and the controller on a copy of robots/crane_x7 loaded as a library. Run with
# -DDYNID, -DSYMOROC, -DWRITE_EXPORT, -DURDF_DIR, -DWORK, -DSOURCE_ROBOTS, -DROBOT_CACHE.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(ENV{SYMORO_CACHE_DIR} ${WORK}/cache)
include(${CMAKE_CURRENT_LIST_DIR}/cli_test_helpers.cmake)

run_command(0 out ${SYMOROC} model ${URDF_DIR}/ur5_robot.urdf -o ${WORK}/robots/ur5 --name ur5)
execute_process(COMMAND ${WRITE_EXPORT} ur5 ${WORK}/export.csv 40 5 RESULT_VARIABLE code)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "write_export ur5 failed")
endif()
set(columns --name arm --time stamp_ms --time-unit ms --q "{name}_pos" --qd "{name}_vel" --tau "{name}_eff" --angle deg
    --split 0.7)

foreach(way loaded compiled)
  if(way STREQUAL "loaded")
    set(robot ${WORK}/robots/ur5)  # a folder: its library
  else()
    set(robot ur5)  # robots/ur5, compiled into dynid
  endif()
  run(0 out import --robot ${robot} -o ${WORK}/${way}-data ${WORK}/export.csv ${columns})
  if(way STREQUAL "loaded")
    expect("${out}" "ur5: built .*libur5.so")  # the first use builds the library
  endif()
  run(0 out identify --robot ${robot} --model full --data ${WORK}/${way}-data -o ${WORK}/${way}-study --interval 10
      --consistency physical)
  if(way STREQUAL "loaded" AND out MATCHES "built ")
    message(FATAL_ERROR "the second use rebuilt the library:\n${out}")
  endif()
  expect("${out}" "validation arm_heldout")
  file(READ ${WORK}/${way}-study/report/parameters.yaml params_${way})
  file(READ ${WORK}/${way}-study/validation.yaml validation_${way})
  run(0 out predict --robot ${robot} --model full --params ${WORK}/${way}-study/report/parameters.yaml
      ${WORK}/${way}-data -o ${WORK}/${way}-predict)
  set(predict_${way} "${out}")
  # The 95 % band from the study's report/uncertainty.yaml: the held-out run inside it 90-98 % of the time.
  expect("${out}" "inside the 95 % band:[^\n]*\\(all 9[0-8]\\.[0-9] %\\)\n +all ")  # the last log: held out
  file(READ ${WORK}/${way}-study/report/report.md report)
  expect("${report}" "\\| arm_heldout \\| 9[0-8]\\.[0-9] % \\|")
  # The URDF with consistent inertials nearest the URDF's own (robot.yaml's nominal).
  run(0 out export --robot ${robot} --study ${WORK}/${way}-study --urdf ${WORK}/${way}-urdf/ur5.urdf)
  file(READ ${WORK}/${way}-urdf/ur5.urdf urdf_${way})
  file(READ ${WORK}/${way}-urdf/ur5.standard.yaml standard_${way})
  # The model-gap diagnosis names the offset the export has (joint 6) and writes its variant.
  run(0 out diagnose --robot ${robot} --model full --data ${WORK}/${way}-data -o ${WORK}/${way}-diagnosis)
  expect("${out}" "effect: constant torque offset, joint 6")
  file(READ ${WORK}/${way}-diagnosis/diagnosis.md diagnosis_${way})
  file(READ ${WORK}/${way}-diagnosis/variant.yaml variant_${way})
endforeach()

# The same numbers both ways (the files name the same robot, its folders' digests aside).
foreach(kind params validation urdf standard diagnosis variant)
  string(REGEX REPLACE "[0-9a-f]{32}" "<digest>" a "${${kind}_loaded}")
  string(REGEX REPLACE "[0-9a-f]{32}" "<digest>" b "${${kind}_compiled}")
  foreach(v a b)  # the folders' paths
    string(REGEX REPLACE "(data|study|folder|dataset)[^\n]*" "" ${v} "${${v}}")
    string(REGEX REPLACE "/[^ \n]*/ur5/(controller|robot|twin).yaml" "<robot folder>/\\1.yaml" ${v} "${${v}}")
    string(REGEX REPLACE "/[^ \n]*/ur5([ )])" "<robot folder>\\1" ${v} "${${v}}")
    string(REGEX REPLACE "Study: [^\n]*" "" ${v} "${${v}}")
  endforeach()
  if(NOT a STREQUAL b)
    file(WRITE ${WORK}/${kind}_loaded.txt "${a}")
    file(WRITE ${WORK}/${kind}_compiled.txt "${b}")
    message(FATAL_ERROR "${kind}: the loaded library's study differs from the compiled robot's "
                        "(${WORK}/${kind}_loaded.txt, ${WORK}/${kind}_compiled.txt)")
  endif()
endforeach()
string(REGEX MATCHALL "RMSE[^\n]*" a "${predict_loaded}")
string(REGEX MATCHALL "RMSE[^\n]*" b "${predict_compiled}")
if(NOT a STREQUAL b OR a STREQUAL "")
  message(FATAL_ERROR "predict differs:\n${predict_loaded}\n---\n${predict_compiled}")
endif()

# Collision detection with the identified model of the robot never compiled (dynid observer):
# thresholds from the dataset's held-out run (no contact), then a second export where the elbow
# meets a 2 N m contact 12 s into the log (it starts at 12.5 s; 0.2 s, 2 ms ramps) that the
# logged torque does not show: one event, on the elbow, within 10 ms; none on the runs without.
run(0 out observer --robot ${WORK}/robots/ur5 --params ${WORK}/loaded-study/report/parameters.yaml
    ${WORK}/loaded-data -o ${WORK}/observer-quiet)
expect("${out}" "arm_1 +28000 samples: 0 events")
expect("${out}" "arm_heldout_1 +12000 samples: 0 events")
execute_process(COMMAND ${WRITE_EXPORT} ur5 ${WORK}/contact.csv 20 9 0 3,12,0.2,2 RESULT_VARIABLE code)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "write_export ur5 (contact) failed")
endif()
run(0 out import --robot ${WORK}/robots/ur5 -o ${WORK}/contact-data ${WORK}/contact.csv ${columns})
run(0 out observer --robot ${WORK}/robots/ur5 --params ${WORK}/loaded-study/report/parameters.yaml
    ${WORK}/contact-data -o ${WORK}/observer-contact --thresholds ${WORK}/observer-quiet/thresholds.yaml)
expect("${out}" "arm_1 +14000 samples: 1 event\n +t = 24\\.50[0-9] s  elbow_joint  peak \\+[12]\\.[0-9]+")
expect("${out}" "arm_heldout_1 +6000 samples: 0 events")
file(READ ${WORK}/observer-contact/events.csv events)
expect("${events}" "arm_1,elbow_joint,24\\.50[0-9]*,")
# Without thresholds or a held-out run to make them, it says what to give; other gains than the
# thresholds' are refused.
run(2 out observer --robot ${WORK}/robots/ur5 --params ${WORK}/loaded-study/report/parameters.yaml
    ${WORK}/contact-data/arm.csv -o ${WORK}/observer-none)
expect("${out}" "no thresholds: give --thresholds")
run(2 out observer --robot ${WORK}/robots/ur5 --params ${WORK}/loaded-study/report/parameters.yaml --gain 100
    ${WORK}/contact-data -o ${WORK}/observer-gain --thresholds ${WORK}/observer-quiet/thresholds.yaml)
expect("${out}" "made with other gains")

# Payload identification on the robot never compiled (dynid payload): an export of the arm
# carrying a 1.2 kg body (CoM [10, -20, 60] mm, inertia about it [4, 5, 3] 1e-3 kg m^2, Ixy
# 0.4e-3, in the URDF tip link's frame) on top of the study's parameters: the mass within 2 %,
# the CoM within 3 mm, the inertia within 15 %, in that frame; and the known-mass case.
execute_process(COMMAND ${WRITE_EXPORT} ur5 ${WORK}/payload.csv 40 7 0 - 1.2,0.01,-0.02,0.06,0.004,0.005,0.003,0.0004,0,0
                RESULT_VARIABLE code)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "write_export ur5 (payload) failed")
endif()
run(0 out import --robot ${WORK}/robots/ur5 -o ${WORK}/payload-data ${WORK}/payload.csv ${columns})
run(0 out payload --robot ${WORK}/robots/ur5 --params ${WORK}/loaded-study/report/parameters.yaml
    ${WORK}/payload-data -o ${WORK}/payload)
expect("${out}" "in the flange frame wrist_3_link")
expect("${out}" "mass +1\\.(1[89]|2[0-2])[0-9]* kg")
expect("${out}" "com +\\[ *([7-9]|1[0-2])\\.[0-9], -(1[7-9]|2[0-2])\\.[0-9], (5[7-9]|6[0-2])\\.[0-9]\\] mm")
expect("${out}" "Ixx 0\\.00(3[4-9]|4[0-5])[0-9]* Iyy 0\\.00(4[3-9]|5[0-6])[0-9]* Izz 0\\.00(2[6-9]|3[0-4])")
# The arm's timing by default (its parameters file's torque_delay_ms), another given with a warning.
expect("${out}" "torque delay 0 ms \\(the arm's, from [^)]*loaded-study/report/parameters.yaml\\)")
file(READ ${WORK}/loaded-study/report/parameters.yaml params)
string(REPLACE "torque_delay_ms: 0\n" "torque_delay_ms: 1.5\n" shifted "${params}")
file(WRITE ${WORK}/shifted-parameters.yaml "${shifted}")
run(0 out payload --robot ${WORK}/robots/ur5 --params ${WORK}/shifted-parameters.yaml ${WORK}/payload-data
    -o ${WORK}/payload-shifted)
expect("${out}" "torque delay 1.5 ms \\(the arm's, from [^)]*shifted-parameters.yaml\\)")
run(0 out payload --robot ${WORK}/robots/ur5 --params ${WORK}/shifted-parameters.yaml ${WORK}/payload-data
    -o ${WORK}/payload-told --torque-delay 0)
expect("${out}" "torque delay 0 ms \\(given\\)")
expect("${out}" "warning: --torque-delay 0 ms, but [^ ]*shifted-parameters.yaml was identified at 1.5 ms")
file(READ ${WORK}/payload/payload.urdf urdf)
expect("${urdf}" "<parent link=\"wrist_3_link\"/>")
file(READ ${WORK}/payload/payload.yaml yaml)
expect("${yaml}" "ur: \"set_target_payload\\(1\\.")
run(2 out payload --robot ${WORK}/robots/ur5 --params ${WORK}/loaded-study/report/parameters.yaml
    ${WORK}/payload-data -o ${WORK}/payload)
expect("${out}" "payload.yaml exists")
# A controller's CSV export without reference columns cannot instrument the fit.
run(2 out payload --robot ${WORK}/robots/ur5 --params ${WORK}/loaded-study/report/parameters.yaml
    ${WORK}/payload-data -o ${WORK}/payload-iv --instruments reference)
expect("${out}" "reference instruments: [a-z_]+ has no reference columns \\(q_ref, qd_ref, qdd_ref\\)")
run(0 out payload --robot ${WORK}/robots/ur5 --params ${WORK}/loaded-study/report/parameters.yaml --mass 1.2
    ${WORK}/payload-data -o ${WORK}/payload-known)
expect("${out}" "mass +1\\.2 kg \\(given\\)")
expect("${out}" "com +\\[ *([7-9]|1[0-2])\\.[0-9], -(1[7-9]|2[0-2])\\.[0-9], (5[7-9]|6[0-2])\\.[0-9]\\] mm")
# With a tare: an export of the arm without the body (another motion and noise); the body within
# the same bounds, and the tare's record in payload.yaml.
execute_process(COMMAND ${WRITE_EXPORT} ur5 ${WORK}/tare.csv 40 8 0 RESULT_VARIABLE code)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "write_export ur5 (tare) failed")
endif()
run(0 out import --robot ${WORK}/robots/ur5 -o ${WORK}/tare-data ${WORK}/tare.csv ${columns})
run(0 out payload --robot ${WORK}/robots/ur5 --params ${WORK}/loaded-study/report/parameters.yaml
    ${WORK}/payload-data --tare ${WORK}/tare-data -o ${WORK}/payload-tared)
expect("${out}" "tare: [0-9]+ samples without the payload")
expect("${out}" "mass +1\\.(1[89]|2[0-2])[0-9]* kg")
expect("${out}" "com +\\[ *([7-9]|1[0-2])\\.[0-9], -(1[7-9]|2[0-2])\\.[0-9], (5[7-9]|6[0-2])\\.[0-9]\\] mm")
expect("${out}" "Ixx 0\\.00(3[4-9]|4[0-5])[0-9]* Iyy 0\\.00(4[3-9]|5[0-6])[0-9]* Izz 0\\.00(2[6-9]|3[0-4])")
file(READ ${WORK}/payload-tared/payload.yaml yaml)
expect("${yaml}" "\ntare: {samples: [0-9]+, standard: \\[")

# The payload into the user's URDF beside the identified inertials (export --into --payload): a
# link on the tip link; the model's own URDF holds it on frame 6's link at the tip's pose.
run(0 out export --robot ${WORK}/robots/ur5 --study ${WORK}/loaded-study --urdf ${WORK}/payload-urdf/ur5.urdf
    --into ${URDF_DIR}/ur5_robot.urdf --payload ${WORK}/payload/payload.yaml)
expect("${out}" "payload: 1\\.(1[89]|2[0-2])[0-9]* kg on wrist_3_link")
file(READ ${WORK}/payload-urdf/ur5.urdf urdf)
expect("${urdf}" "<joint name=\"payload_joint\" type=\"fixed\">\n +<parent link=\"wrist_3_link\"/>")
run(0 out export --robot ${WORK}/robots/ur5 --study ${WORK}/loaded-study --urdf ${WORK}/payload-model/ur5.urdf
    --payload ${WORK}/payload/payload.yaml)
file(READ ${WORK}/payload-model/ur5.urdf urdf)
expect("${urdf}" "<parent link=\"wrist_3_joint_link\"/>\n +<child link=\"payload\"/>\n +<origin xyz=\"0 0 0\" rpy=\"1\\.57")
# A 20 s wrist motion for the payload (dynid excite --payload): the wrist joints move, the rest holds.
run(0 out excite --robot ${WORK}/robots/ur5 --payload --starts 1 -o ${WORK}/payload-excite)
expect("${out}" "payload excitation: wrist_1_joint, wrist_2_joint, wrist_3_joint move")
expect("${out}" "PL01: 20\\.0 s; payload \\(10 parameters on link 6\\): scaled kappa [1-9]")

# An edited robot folder is another library: a joint limit changed, the library is rebuilt.
file(READ ${WORK}/robots/ur5/robot.yaml yaml)
string(REPLACE "velocity: 3.15" "velocity: 3.0" yaml "${yaml}")
file(WRITE ${WORK}/robots/ur5/robot.yaml "${yaml}")
run(0 out identify --robot ${WORK}/robots/ur5 --model full --data ${WORK}/loaded-data -o ${WORK}/edited-study
    --interval 10 --no-report)
expect("${out}" "ur5: built ")
# A robot without a digital twin says so.
run(2 out twin run --robot ${WORK}/robots/ur5 --trajectory AG02 -o ${WORK}/x)
expect("${out}" "robot 'ur5' has no digital twin \\(.*twin.yaml not found\\)")
run(2 out trajectories --robot ${WORK}/robots/ur5)
expect("${out}" "robot 'ur5' has no trajectory design \\(.*trajectories.yaml not found\\): dynid excite")

# The twin, the trajectories and the controller on a loaded robot: a copy of robots/crane_x7
# elsewhere (its library from the robot cache the fixture robot_libraries built: the same key).
# Its twin's log is the compiled robot's, bit for bit, with every effect on (backlash, payload,
# noise, jitter, dropped samples); the controller drives its twin on the virtual bus.
set(ENV{SYMORO_CACHE_DIR} ${ROBOT_CACHE})
file(COPY ${SOURCE_ROBOTS}/crane_x7 DESTINATION ${WORK}/robots)
file(WRITE ${WORK}/all-effects.yaml "effects:\n  backlash: {enabled: true}\n  payload: {enabled: true}\n"
     "  coulomb: {enabled: true}\n  stribeck: {enabled: true}\n  torque_offset: {enabled: true}\n")
foreach(way loaded compiled)
  if(way STREQUAL "loaded")
    set(robot ${WORK}/robots/crane_x7)
  else()
    set(robot crane_x7)
  endif()
  run(0 out twin run --robot ${robot} --trajectory PA03 --seed 5 --config ${WORK}/all-effects.yaml -o ${WORK}/twin-${way})
  if(out MATCHES "built ")
    message(FATAL_ERROR "the copy's library was rebuilt, not taken from ${ROBOT_CACHE}:\n${out}")
  endif()
  file(READ ${WORK}/twin-${way}/PA03_t1.csv twin_${way})
  run(0 out trajectories --robot ${robot} --only PA03 V01)
  set(trajectories_${way} "${out}")
endforeach()
if(NOT twin_loaded STREQUAL twin_compiled OR twin_loaded STREQUAL "")
  message(FATAL_ERROR "the loaded robot's twin log differs from the compiled robot's (${WORK}/twin-loaded, ${WORK}/twin-compiled)")
endif()
if(NOT trajectories_loaded STREQUAL trajectories_compiled)
  message(FATAL_ERROR "trajectories differ:\n${trajectories_loaded}\n---\n${trajectories_compiled}")
endif()
run(0 out control --robot ${WORK}/robots/crane_x7 --virtual --trajectory AG02 --seconds 0.5 -o ${WORK}/control.csv)
expect("${out}" "completed; torque off confirmed")
