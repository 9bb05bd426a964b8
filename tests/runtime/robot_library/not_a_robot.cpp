// A shared object without the robot library's entry points (test_robot_library: refused).
extern "C" __attribute__((visibility("default"))) int some_other_library(void) { return 1; }
