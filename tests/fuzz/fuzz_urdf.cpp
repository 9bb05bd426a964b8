// libFuzzer entry point for symoroc model's URDF reader (the chain from a URDF: XML, urdfdom, the
// value checks, the chain search, the modified DH frames and the inertials merged into them): the
// input as a .urdf file. Any input must either read or throw InputError; another exception, a
// crash, a sanitizer report or a hang is a bug.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_files.hpp"
#include "symoro/codegen/robot_spec.hpp"
#include "urdf_chain.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path urdf = symoro::fuzz::scratch() / "robot.urdf";
  symoro::fuzz::write_bytes(urdf, std::string_view(reinterpret_cast<const char*>(data), size));
  try {
    const symoro::codegen::modeling::UrdfChain chain = symoro::codegen::modeling::read_urdf_chain(urdf.string(), {});
    symoro::fuzz::check(!chain.par_text.empty() && !chain.robot_yaml.empty());
  } catch (const symoro::codegen::InputError&) {
  }
  return 0;
}
