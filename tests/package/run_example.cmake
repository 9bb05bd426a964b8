# ctest driver: install the built project into a scratch prefix, build tests/package against
# it with find_package(symoro), and run the examples; then the installed dynid on a URDF and a ROS 2
# bag (below). Arguments: -DBUILD_DIR -DSOURCE_DIR -DWORK_DIR -DURDF -DWRITE_EXPORT -DNODE -DBAG_WRITER
file(REMOVE_RECURSE "${WORK_DIR}")
foreach(step
    "${CMAKE_COMMAND};--install;${BUILD_DIR};--prefix;${WORK_DIR}/prefix"
    "${CMAKE_COMMAND};-S;${SOURCE_DIR}/tests/package;-B;${WORK_DIR}/build;-DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix"
    "${CMAKE_COMMAND};--build;${WORK_DIR}/build"
    "${WORK_DIR}/build/crane_x7_example"
    "${WORK_DIR}/build/identify_example")
  execute_process(COMMAND ${step} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "step failed (${rc}): ${step}")
  endif()
endforeach()

# The installed dynid and symoroc on a URDF they were never built with and a ROS 2 bag (written
# by the MCAP project's own writer from write_export's synthetic UR5 log): import, physical
# identification, and the identified arm as URDF and MJCF (issue: a URDF owner's path through an
# installed dynid). -DURDF, -DWRITE_EXPORT, -DNODE, -DBAG_WRITER.
set(bin "${WORK_DIR}/prefix/bin")
set(ENV{SYMORO_CACHE_DIR} "${WORK_DIR}/cache")
foreach(step
    "${bin}/symoroc;model;${URDF};-o;${WORK_DIR}/robots/my_arm;--name;my_arm"
    "${WRITE_EXPORT};ur5;${WORK_DIR}/arm.json;20;3"
    "${NODE};${BAG_WRITER};${WORK_DIR}/arm.json"
    "${bin}/dynid;import;--robot;${WORK_DIR}/robots/my_arm;-o;${WORK_DIR}/data;${WORK_DIR}/arm.mcap;--split;0.7"
    "${bin}/dynid;identify;--robot;${WORK_DIR}/robots/my_arm;--data;${WORK_DIR}/data;-o;${WORK_DIR}/study;--consistency;physical"
    "${bin}/dynid;export;--robot;${WORK_DIR}/robots/my_arm;--study;${WORK_DIR}/study;--urdf;${WORK_DIR}/out/my_arm.urdf;--mjcf;${WORK_DIR}/out/my_arm.xml")
  execute_process(COMMAND ${step} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "step failed (${rc}): ${step}\n${out}\n${err}")
  endif()
endforeach()
file(READ "${WORK_DIR}/out/my_arm.xml" mjcf)
if(NOT mjcf MATCHES "<mujoco model=\"my_arm\">" OR NOT mjcf MATCHES "armature=")
  message(FATAL_ERROR "${WORK_DIR}/out/my_arm.xml is not the identified arm's MJCF")
endif()
