# A URDF owner's path, end to end, on a robot dynid was never built with: symoroc model from the
# UR5's URDF, a ROS 2 bag of the arm (written by the MCAP project's own writer from a log that
# write_export synthesizes with Coulomb friction and an offset the model is not told of), dynid
# import of the bag with a 70/30 split, identification on the physical path, and dynid export to
# a URDF and a MuJoCo model. The same through the compiled robots/ur5: the MJCF is the same text
# (tests/runtime/test_export_mjcf.cpp checks the compiled UR5's MJCF against MuJoCo's own inverse
# dynamics). Run with -DDYNID, -DSYMOROC, -DWRITE_EXPORT, -DNODE, -DBAG_WRITER, -DURDF_DIR, -DWORK.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(ENV{SYMORO_CACHE_DIR} ${WORK}/cache)
include(${CMAKE_CURRENT_LIST_DIR}/cli_test_helpers.cmake)

run_command(0 out ${SYMOROC} model ${URDF_DIR}/ur5_robot.urdf -o ${WORK}/robots/ur5 --name ur5)
run_command(0 out ${WRITE_EXPORT} ur5 ${WORK}/arm.json 40 5)
run_command(0 out ${NODE} ${BAG_WRITER} ${WORK}/arm.json)

foreach(way loaded compiled)
  if(way STREQUAL "loaded")
    set(robot ${WORK}/robots/ur5)
  else()
    set(robot ur5)
  endif()
  run(0 out import --robot ${robot} -o ${WORK}/${way}-data ${WORK}/arm.mcap --split 0.7)
  expect("${out}" "1 MCAP file, [0-9]+ messages on /joint_states \\(sensor_msgs/msg/JointState\\); other topics: /status")
  expect("${out}" "names the robot has not, ignored: gripper_joint")
  expect("${out}" "velocity: measured")
  file(READ ${WORK}/${way}-data/import.yaml record)
  expect("${record}" "bag: \\{topic: \"?/joint_states\"?, stamp: header, effort: torque")
  run(0 out identify --robot ${robot} --model full --data ${WORK}/${way}-data -o ${WORK}/${way}-study --interval 10
      --consistency physical)
  expect("${out}" "validation arm_heldout")
  run(0 out export --robot ${robot} --study ${WORK}/${way}-study --urdf ${WORK}/${way}-out/ur5.urdf
      --mjcf ${WORK}/${way}-out/ur5.xml)
  expect("${out}" "mjcf: .*ur5.xml \\(rotor inertia as each joint's armature")
  expect("${out}" "rotor inertia has no URDF field.*ur5.xml \\(each joint's armature\\)")
  file(READ ${WORK}/${way}-out/ur5.xml mjcf_${way})
  expect("${mjcf_${way}}" "<joint name=\"elbow_joint\" type=\"hinge\"[^\n]* armature=\"[0-9.e-]+\" damping=\"[0-9.e-]+\" frictionloss=\"[0-9.e-]+\"/>")
  expect("${mjcf_${way}}" "<motor name=\"wrist_3_joint\" joint=\"wrist_3_joint\"")
  # The notes before <mujoco> name the study's and the robot's folders; the model itself is the
  # same text both ways.
  string(FIND "${mjcf_${way}}" "<mujoco " at)
  string(SUBSTRING "${mjcf_${way}}" ${at} -1 mjcf_${way})
endforeach()
if(NOT mjcf_loaded STREQUAL mjcf_compiled)
  file(WRITE ${WORK}/mjcf_loaded.xml "${mjcf_loaded}")
  file(WRITE ${WORK}/mjcf_compiled.xml "${mjcf_compiled}")
  message(FATAL_ERROR "the loaded robot's MJCF differs from the compiled robot's (${WORK}/mjcf_*.xml)")
endif()

# A bag without the robot's joints, or on another topic, is refused naming the bag.
run(1 out import --robot ${WORK}/robots/ur5 -o ${WORK}/none ${WORK}/arm.mcap --topic /arm/joint_states)
expect("${out}" "arm.mcap.*no message on topic /arm/joint_states; the bag has /joint_states \\([0-9]+\\), /status")
