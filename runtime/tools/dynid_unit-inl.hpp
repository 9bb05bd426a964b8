// What a generated unit (units/<robot>/*.cpp) compiles: commands for one robot, each instantiated
// for the model(s) it runs on, added to the command's table. Command is a struct with `Options` and
// `template <class Full, class Model> static void run(const Common&, const Options&)`.
#pragma once

#include <cstddef>
#include <string>
#include <tuple>
#include <type_traits>

#include "dynid_dispatch.hpp"

namespace symoro::dynid::units {

template <class Model>
std::string variant_label() {
  const std::string v = Model::variant_name;
  return v.empty() ? "full" : v;
}

// Commands on the robot's full model (I and Tail unused: one unit per robot).
template <class Command, class Full, class Identified, class Models, std::size_t I, bool Tail>
void add_full(CommandTable<typename Command::Options>& table, const char* robot) {
  table.add(robot, "", &Command::template run<Full, Full>);
}

// Commands on the robot's identified model (robot.yaml's `identified`).
template <class Command, class Full, class Identified, class Models, std::size_t I, bool Tail>
void add_identified(CommandTable<typename Command::Options>& table, const char* robot) {
  table.add(robot, "", &Command::template run<Full, Identified>);
}

// Commands on any model (--model <variant>): model I of Models, and with Tail every later one
// too (the generated units take I = 0 with Tail: every model of the robot).
template <class Command, class Full, class Identified, class Models, std::size_t I, bool Tail>
void add_variants(CommandTable<typename Command::Options>& table, const char* robot) {
  if constexpr (I < std::tuple_size_v<Models>) {
    using Model = std::tuple_element_t<I, Models>;
    const auto run = &Command::template run<Full, Model>;
    table.add(robot, variant_label<Model>(), run);
    if constexpr (std::is_same_v<Model, Identified>) table.add(robot, "", run);
    if constexpr (Tail) add_variants<Command, Full, Identified, Models, I + 1, true>(table, robot);
  }
}

}  // namespace symoro::dynid::units
