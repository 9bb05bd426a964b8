// A shared object that claims another robot ABI version (test_robot_library: the loader refuses it).
#include "symoro/robot_abi.h"

extern "C" __attribute__((visibility("default"))) unsigned symoro_robot_abi_version(void) { return 999; }
extern "C" __attribute__((visibility("default"))) const symoro_abi_robot* symoro_robot(void) { return nullptr; }
