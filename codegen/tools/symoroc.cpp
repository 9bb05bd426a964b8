// symoroc: the model compiler's command line (generate, check, info, model, build).
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>

#include "symoro/codegen/generator.hpp"
#include "symoro/codegen/modeling.hpp"
#include "symoro/codegen/robot_library.hpp"
#include "symoro/codegen/robot_name.hpp"
#include "symoro/grammar/parser.hpp"

#include <fcntl.h>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace symoro::codegen;

namespace {

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Writes files that belong together (a robot folder's model files, a robot's headers) all or
// none: each goes to "<name>.tmp", complete and fsynced, before any takes its name, so that a
// failure (a full disk) leaves every file as it was and no temporary file behind, and says why.
void write_all_or_none(const std::vector<std::pair<fs::path, std::string>>& files) {
  std::vector<fs::path> temps;
  auto fail = [&](const fs::path& file, int error) {
    for (const auto& t : temps) ::unlink(t.c_str());
    const std::string why = error == ENOSPC ? "no space left on device" : std::strerror(error);
    throw std::runtime_error("cannot write " + file.string() + " (" + why + "); no file of the " +
                             std::to_string(files.size()) + " was changed");
  };
  for (const auto& [file, text] : files) {
    std::error_code ec;
    if (file.has_parent_path()) fs::create_directories(file.parent_path(), ec);
    if (ec) fail(file, ec.value());
    const fs::path tmp = file.string() + ".tmp";
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) fail(file, errno);
    temps.push_back(tmp);
    const char* p = text.data();
    std::size_t left = text.size();
    int error = 0;
    while (left > 0 && error == 0) {
      const ssize_t done = ::write(fd, p, left);
      if (done < 0 && errno == EINTR) continue;
      if (done <= 0) {
        error = done < 0 ? errno : EIO;
      } else {
        p += done;
        left -= static_cast<std::size_t>(done);
      }
    }
    if (error == 0 && ::fsync(fd) != 0) error = errno;
    if (::close(fd) != 0 && error == 0) error = errno;
    if (error != 0) fail(file, error);
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    std::error_code ec;
    fs::rename(temps[i], files[i].first, ec);
    if (ec) {
      for (std::size_t k = i; k < temps.size(); ++k) ::unlink(temps[k].c_str());
      throw std::runtime_error("cannot rename " + temps[i].string() + " to " + files[i].first.string() + ": " +
                               ec.message());
    }
  }
}

std::vector<fs::path> robot_dirs(const fs::path& robots) {
  std::vector<fs::path> out;
  if (!fs::is_directory(robots)) throw std::runtime_error(robots.string() + ": not a directory");
  for (const auto& e : fs::directory_iterator(robots))
    if (e.is_directory() && fs::exists(e.path() / "robot.yaml")) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

std::set<std::string> files_under(const fs::path& root, const fs::path& dir) {
  std::set<std::string> out;
  if (!fs::is_directory(dir)) return out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) out.insert(fs::relative(e.path(), root).generic_string());
  return out;
}

int first_difference_line(const std::string& a, const std::string& b) {
  int line = 1;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
    if (a[i] != b[i]) return line;
    if (a[i] == '\n') ++line;
  }
  return line;
}

int generate(const std::vector<std::string>& dirs, const std::string& out_root) {
  for (const auto& dir : dirs) {
    RobotModel robot = load_robot(dir);
    const Generation gen = generate_robot(robot);
    std::set<std::string> fresh;
    std::vector<std::pair<fs::path, std::string>> files;
    for (const auto& f : gen.files) {
      files.emplace_back(fs::path(out_root) / f.path, f.content);
      fresh.insert(f.path);
    }
    write_all_or_none(files);
    for (const auto& old : files_under(out_root, fs::path(out_root) / robot.name))
      if (!fresh.count(old)) fs::remove(fs::path(out_root) / old);  // stale output of an old variant
    fmt::print("{}: {} files, {} models\n", robot.name, gen.files.size(), gen.models.size());
  }
  return 0;
}

int check(const std::string& robots, const std::string& generated) {
  int problems = 0;
  std::set<std::string> names;
  for (const auto& dir : robot_dirs(robots)) {
    RobotModel robot = load_robot(dir.string());
    names.insert(robot.name);
    const Generation gen = generate_robot(robot);
    std::set<std::string> expected;
    for (const auto& f : gen.files) {
      expected.insert(f.path);
      const fs::path p = fs::path(generated) / f.path;
      if (!fs::exists(p)) {
        fmt::print("missing   {}\n", p.string());
        ++problems;
        continue;
      }
      const std::string on_disk = read_text(p);
      if (on_disk != f.content) {
        fmt::print("differs   {} (from line {})\n", p.string(), first_difference_line(on_disk, f.content));
        ++problems;
      }
    }
    for (const auto& f : files_under(generated, fs::path(generated) / robot.name))
      if (!expected.count(f)) {
        fmt::print("extra     {}\n", (fs::path(generated) / f).string());
        ++problems;
      }
  }
  if (fs::is_directory(generated))
    for (const auto& e : fs::directory_iterator(generated))
      if (e.is_directory() && !names.count(e.path().filename().string())) {
        fmt::print("stale     {} (no robots/{})\n", e.path().string(), e.path().filename().string());
        ++problems;
      }
  if (problems) {
    fmt::print(
        "symoroc check: {} difference(s) between {} and a fresh generation from {}.\n"
        "Run: symoroc generate {}/* -o {}\n",
        problems, generated, robots, robots, generated);
    return 1;
  }
  fmt::print("symoroc check: {} is up to date ({} robots).\n", generated, names.size());
  return 0;
}

int info(const std::string& dir) {
  RobotModel robot = load_robot(dir);
  const Generation gen = generate_robot(robot);
  fmt::print("robot {} ({} joints, {} standard parameters, {} base parameters)\n", robot.name, robot.n,
             robot.standard.size(), robot.base.size());
  if (!robot.spec.description.empty()) fmt::print("  {}\n", robot.spec.description);
  fmt::print("joints:\n");
  for (int j = 0; j < robot.n; ++j) {
    const auto& js = robot.spec.joints[j];
    fmt::print("  {:>2} {:<18} {} {:<6} [{:.4g}, {:.4g}]  |qd| <= {:.4g}  |tau| <= {:.4g}  audit [{:.4g}, {:.4g}]\n",
               j + 1, js.name, robot.frames[j].sigma ? "prismatic" : "revolute ", robot.q[j], js.lower, js.upper,
               js.velocity, js.effort, js.audit_lower, js.audit_upper);
  }
  for (const auto& m : gen.models) {
    fmt::print("\nmodel {}: {} identified parameters", m.name, m.identified.size());
    if (!m.fixed.empty()) fmt::print(", {} fixed", m.fixed.size());
    fmt::print("\n");
    if (!m.description.empty()) fmt::print("  {}\n", m.description);
    std::string line = " ";
    for (std::size_t i = 0; i < m.identified.size(); ++i) {
      std::string item = fmt::format(" {}:{} [{}]", i, m.identified[i].name, m.identified[i].unit);
      if (line.size() + item.size() > 100) {
        fmt::print("{}\n", line);
        line = " ";
      }
      line += item;
    }
    fmt::print("{}\n", line);
    if (!m.fixed.empty()) {
      std::string fixed = "  fixed:";
      for (const auto& [name, v] : m.fixed) fixed += fmt::format(" {}={}", name, v);
      fmt::print("{}\n", fixed);
    }
    if (!m.effects.empty()) {
      fmt::print("  effects (torque += parameter * term on its joint):\n");
      for (const auto& [name, term] : m.effects) {
        std::string unit;
        for (const auto& p : m.identified)
          if (p.name == name) unit = p.unit;
        fmt::print("    {:<10} [{}] * {}\n", name, unit, term);
      }
    }
    fmt::print("  {:<20} {:>7} {:>7} {:>5} {:>5} {:>5} {:>5} {:>5} {:>5} {:>7}\n", "function", "add", "mul", "div",
               "neg", "pow", "trig", "sign", "exp", "total");
    for (const auto& f : m.functions)
      fmt::print("  {:<20} {:>7} {:>7} {:>5} {:>5} {:>5} {:>5} {:>5} {:>5} {:>7}\n", f.name, f.ops.add, f.ops.mul,
                 f.ops.div, f.ops.neg, f.ops.pow, f.ops.trig, f.ops.sign, f.ops.exp, f.ops.total());
  }
  return 0;
}

// Writes a robot folder's model files computed from its .par or URDF. Every file is computed
// before any is written; a file that exists with other content (a robot.yaml the user edited)
// is replaced only with --force.
int model(const std::string& input, const std::string& out_dir, const ModelingOptions& options, bool force) {
  const fs::path in(input);
  const bool urdf = in.extension() == ".urdf" || in.extension() == ".xml";
  if (!urdf && in.extension() != ".par") throw std::runtime_error(input + ": symoroc model reads a .par or a .urdf");
  const fs::path dir = fs::path(out_dir).lexically_normal();
  // The folder's name becomes the robot's namespace at symoroc generate: refuse it now.
  const std::string folder = (dir.has_filename() ? dir.filename() : dir.parent_path().filename()).string();
  if (const std::string why = robot_name_problem(folder); !why.empty())
    throw std::runtime_error(out_dir + ": " + why + " (the folder's name)");
  Modeling m = urdf ? model_from_urdf(input, options) : model_from_par(input, options);
  if (!urdf) m.files.insert(m.files.begin(), {in.filename().string(), read_text(in)});
  std::vector<std::string> changed;
  for (const auto& f : m.files)
    if (fs::exists(dir / f.name) && read_text(dir / f.name) != f.text) changed.push_back(f.name);
  if (!changed.empty() && !force) {
    std::string list;
    for (const auto& c : changed) list += " " + c;
    throw std::runtime_error(dir.string() + " already has other versions of" + list + ": pass --force to replace them");
  }
  std::vector<std::pair<fs::path, std::string>> files;
  for (const auto& f : m.files) files.emplace_back(dir / f.name, f.text);
  write_all_or_none(files);
  fmt::print("{}: {} base parameters, {} files in {}\n", m.robot, m.base_parameters.size(), m.files.size(),
             dir.string());
  for (const auto& note : m.notes) fmt::print("  {}\n", note);
  if (!fs::exists(dir / "robot.yaml"))
    fmt::print("  {} has no robot.yaml yet: write one (joints, limits, constants) before symoroc generate\n",
               dir.string());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"symoroc: compiles OpenSYMORO model files into specialized, autodiff-ready C++"};
  app.require_subcommand(1);

  std::vector<std::string> gen_dirs;
  std::string out_root = "generated";
  auto* gen = app.add_subcommand("generate", "Generate the headers of one or more robot folders");
  gen->add_option("robot_dirs", gen_dirs, "robots/<name> folders")->required()->check(CLI::ExistingDirectory);
  gen->add_option("-o,--output", out_root, "Output root (headers go to <output>/<name>/include)")
      ->capture_default_str();

  std::string robots = "robots", generated = "generated";
  auto* chk = app.add_subcommand("check", "Fail when the generated headers differ from a fresh generation");
  chk->add_option("--robots", robots, "Folder of robot folders")->capture_default_str();
  chk->add_option("--generated", generated, "Folder of generated headers")->capture_default_str();

  std::string info_dir;
  auto* inf = app.add_subcommand("info", "Parameters, counts and operation counts of a robot");
  inf->add_option("robot_dir", info_dir, "robots/<name>")->required()->check(CLI::ExistingDirectory);

  std::string model_input, model_out;
  auto* mdl =
      app.add_subcommand("model", "Compute a robot's model files (base parameters, dynamics, geometry) from its .par");
  mdl->add_option("description", model_input, "<robot>.urdf or <robot>.par")->required()->check(CLI::ExistingFile);
  mdl->add_option("-o,--output", model_out, "The robot folder to write (robots/<name>)")->required();
  ModelingOptions model_options;
  mdl->add_option("--frame", model_options.frame, "Frame of the geometric model and the Jacobian (default: the last)");
  mdl->add_option("--name", model_options.name, "The robot's name (URDF: default the URDF's)");
  mdl->add_option("--base-link", model_options.base_link, "URDF: the chain's first link (default: the root)");
  mdl->add_option("--tip-link", model_options.tip_link,
                  "URDF: the chain's last link (default: where the moving joints end)");
  std::vector<std::string> locks;
  mdl->add_option("--lock", locks, "URDF: joint=position for a moving joint off the chain (default 0)");
  bool no_ia = false, no_fv = false, no_fs = false, force = false;
  mdl->add_flag("--no-rotor-inertia", no_ia, "URDF: no IA parameter per joint");
  mdl->add_flag("--no-viscous", no_fv, "URDF: no FV (viscous friction) parameter per joint");
  mdl->add_flag("--no-coulomb", no_fs, "URDF: no FS (Coulomb friction) parameter per joint");
  mdl->add_flag("--force", force, "Replace files of the folder that differ");

  std::vector<std::string> build_dirs;
  RobotLibraryOptions build_options;
  std::string build_cache;
  auto* bld = app.add_subcommand("build",
                                 "Compile robot folders into robot libraries (the runtime loads them; "
                                 "dynid and Python build on first use)");
  bld->add_option("robot_dirs", build_dirs, "robots/<name> folders")->required()->check(CLI::ExistingDirectory);
  bld->add_option("--cache", build_cache, "The robot cache (default: $SYMORO_CACHE_DIR, else ~/.cache/symoro/robots)");
  bld->add_option("-j,--jobs", build_options.jobs, "Parallel compiles (default: the machine's cores)");
  bld->add_flag("--force", build_options.force, "Rebuild even when the cache has the library");
  std::string build_objects;
  bld->add_option("--objects", build_objects,
                  "Also write the models' objects, partially linked, to this file (one robot folder): what a program "
                  "linking the robot statically takes, compiled once with its library");

  CLI11_PARSE(app, argc, argv);
  try {
    if (*bld) {
      build_options.cache_dir = build_cache;
      if (!build_objects.empty() && build_dirs.size() != 1)
        throw std::runtime_error("--objects takes one robot folder, not " + std::to_string(build_dirs.size()));
      build_options.objects = build_objects;
      build_options.progress = [](const std::string& line) { std::cerr << line << "\n"; };
      for (const auto& dir : build_dirs) {
        const RobotLibraryBuild b = build_robot_library(dir, build_options);
        std::cout << b.library.string() << "\n";
      }
      return 0;
    }
    if (*gen) return generate(gen_dirs, out_root);
    if (*chk) return check(robots, generated);
    if (*inf) return info(info_dir);
    if (*mdl) {
      for (const auto& l : locks) add_lock(model_options, l);
      model_options.rotor_inertia = !no_ia;
      model_options.viscous = !no_fv;
      model_options.coulomb = !no_fs;
      return model(model_input, model_out, model_options, force);
    }
  } catch (const symoro::grammar::ParseError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "symoroc: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
