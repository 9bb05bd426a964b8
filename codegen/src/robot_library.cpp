#include "symoro/codegen/robot_library.hpp"

#include <dlfcn.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#define XXH_INLINE_ALL  // header-only (Debian libxxhash-dev): no library to link
#include <xxhash.h>

#include "robot_library_config.hpp"  // configured by codegen/CMakeLists.txt
#include "symoro/codegen/generator.hpp"
#include "symoro/robot_abi.h"

extern char** environ;

namespace symoro::codegen {
namespace fs = std::filesystem;

namespace {

std::string hex128(const std::string& bytes) {
  const XXH128_hash_t h = XXH3_128bits(bytes.data(), bytes.size());
  char hex[33];
  std::snprintf(hex, sizeof hex, "%016llx%016llx", static_cast<unsigned long long>(h.high64),
                static_cast<unsigned long long>(h.low64));
  return hex;
}

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "";
}

std::vector<std::string> split_flags(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

// The folder holding include/symoro/robot_abi.h nearest above the program or shared object this
// code was linked into (an installed dynid, symoroc or Python module), else "".
fs::path installed_include_dir() {
  Dl_info info{};
  if (!dladdr(reinterpret_cast<void*>(&default_robot_cache_dir), &info) || !info.dli_fname) return {};
  std::error_code ec;
  fs::path p = fs::canonical(info.dli_fname, ec);
  if (ec) return {};
  for (int up = 0; up < 6 && p.has_parent_path() && p != p.parent_path(); ++up) {
    p = p.parent_path();
    if (fs::exists(p / "include/symoro/robot_abi.h", ec)) return p / "include";
  }
  return {};
}

// The compiler as an executable path: itself when it names a path, else found on PATH.
fs::path resolve_compiler(const std::string& compiler) {
  if (compiler.empty()) return {};
  if (compiler.find('/') != std::string::npos)
    return access(compiler.c_str(), X_OK) == 0 ? fs::path(compiler) : fs::path();
  std::istringstream path(env("PATH"));
  for (std::string dir; std::getline(path, dir, ':');) {
    const fs::path p = fs::path(dir.empty() ? "." : dir) / compiler;
    if (access(p.c_str(), X_OK) == 0) return p;
  }
  return {};
}

// Runs argv with stdout and stderr to `log`; returns the process id.
pid_t spawn(const std::vector<std::string>& argv, const fs::path& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw BuildError("cannot run " + argv[0] + ": " + std::strerror(rc));
  return pid;
}

std::string tail_of(const fs::path& log, std::size_t lines) {
  std::ifstream in(log);
  std::vector<std::string> all;
  for (std::string l; std::getline(in, l);) all.push_back(l);
  std::string out;
  for (std::size_t i = all.size() > lines ? all.size() - lines : 0; i < all.size(); ++i) out += "  " + all[i] + "\n";
  return out;
}

std::string joined(const std::vector<std::string>& argv) {
  std::string s;
  for (const auto& a : argv) s += (s.empty() ? "" : " ") + a;
  return s;
}

// Runs the commands, `jobs` at a time; the first failure throws with its command and log tail.
void run_all(const std::vector<std::vector<std::string>>& commands, const std::vector<fs::path>& logs, int jobs) {
  std::vector<std::pair<pid_t, std::size_t>> running;
  std::size_t next = 0;
  std::string failure;
  while (next < commands.size() || !running.empty()) {
    while (failure.empty() && next < commands.size() && static_cast<int>(running.size()) < jobs) {
      running.emplace_back(spawn(commands[next], logs[next]), next);
      ++next;
    }
    if (running.empty()) break;
    // Only our own children: the host (a Python process, a farm) may have others.
    int status = 0;
    auto it = running.end();
    while (it == running.end()) {
      for (auto r = running.begin(); r != running.end() && it == running.end(); ++r) {
        const bool only = running.size() == 1;
        const pid_t done = waitpid(r->first, &status, only ? 0 : WNOHANG);
        if (done == r->first)
          it = r;
        else if (done < 0 && errno != EINTR)
          throw BuildError(std::string("waiting for the compiler: ") + std::strerror(errno));
      }
      if (it == running.end() && running.size() > 1) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    const std::size_t i = it->second;
    running.erase(it);
    if (failure.empty() && !(WIFEXITED(status) && WEXITSTATUS(status) == 0))
      failure = "the compiler failed (" +
                (WIFEXITED(status) ? "exit " + std::to_string(WEXITSTATUS(status))
                                   : "signal " + std::to_string(WTERMSIG(status))) +
                "): " + joined(commands[i]) + "\n" + tail_of(logs[i], 20) + "(the whole log: " + logs[i].string() + ")";
  }
  if (!failure.empty()) throw BuildError(failure);
}

void write_file(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
  if (!out.flush()) throw BuildError("cannot write " + p.string());
}

std::string c_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

// "crane_x7::reduced" -> ("symoro/crane_x7/reduced/all.hpp", "::symoro::crane_x7::reduced::Model")
std::pair<std::string, std::string> model_names(const std::string& robot, const std::string& summary_name) {
  const std::string variant = summary_name.size() > robot.size() + 2 ? summary_name.substr(robot.size() + 2) : "";
  if (variant.empty()) return {"symoro/" + robot + "/all.hpp", "::symoro::" + robot + "::Model"};
  return {"symoro/" + robot + "/" + variant + "/all.hpp", "::symoro::" + robot + "::" + variant + "::Model"};
}

// The models' objects of a built library (its folder's src/*.o but the entry, robot.o), partially
// linked into one relocatable object at options.objects, for a program that links the robot's
// kernels (compiled_model<Model>()): one file whatever the number of models, replaced whole.
void write_objects(const fs::path& library_dir, const RobotLibraryOptions& options) {
  std::vector<std::string> objects;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(library_dir / "src", ec))
    if (e.path().extension() == ".o" && e.path().filename() != "robot.o") objects.push_back(e.path().string());
  if (objects.empty())
    throw BuildError("the robot library in " + library_dir.string() +
                     " has no model objects (src/*.o): rebuild it with --force");
  std::sort(objects.begin(), objects.end());
  const fs::path out = options.objects;
  fs::create_directories(out.parent_path().empty() ? fs::path(".") : out.parent_path(), ec);
  const fs::path partial = out.string() + ".part-" + std::to_string(getpid());
  std::vector<std::string> link = {resolve_compiler(options.toolchain.compiler).string(), "-r", "-nostdlib", "-o",
                                   partial.string()};
  link.insert(link.end(), objects.begin(), objects.end());
  run_all({link}, {fs::path(out.string() + ".log")}, 1);
  fs::rename(partial, out, ec);
  if (ec) throw BuildError("cannot write " + out.string() + ": " + ec.message());
}

}  // namespace

RobotToolchain RobotToolchain::configured() {
  RobotToolchain t;
  t.compiler = env("SYMORO_CXX").empty() ? SYMORO_CONFIGURED_CXX : env("SYMORO_CXX");
  t.flags = split_flags(SYMORO_CONFIGURED_CXX_FLAGS);
  for (const char* f : {"-std=c++17", "-fPIC", "-fvisibility=hidden", "-fvisibility-inlines-hidden"})
    t.flags.push_back(f);
  fs::path headers = env("SYMORO_INCLUDE_DIR");
  if (headers.empty()) headers = installed_include_dir();
  if (headers.empty()) headers = SYMORO_SOURCE_INCLUDE_DIR;
  t.include_dirs = {headers.string()};
  for (const auto& d : split_flags(SYMORO_CONFIGURED_EXTRA_INCLUDES)) t.include_dirs.push_back(d);
  return t;
}

std::string RobotToolchain::identity() const {
  const fs::path exe = resolve_compiler(compiler);
  if (exe.empty())
    throw BuildError("the compiler '" + compiler + "' is missing (" +
                     (env("SYMORO_CXX").empty() ? "the one symoro was configured with" : "named by SYMORO_CXX") +
                     "): a robot library is compiled from its generated C++; install it, or set SYMORO_CXX to a "
                     "C++17 compiler");
  // Once per compiler and process: every load forms the cache key with it.
  static std::mutex mutex;
  static std::map<std::string, std::string> known;
  const std::lock_guard<std::mutex> lock(mutex);
  if (const auto it = known.find(exe.string()); it != known.end()) return it->second;
  static int calls = 0;
  const fs::path log = fs::temp_directory_path() /
                       ("symoro-cc-version-" + std::to_string(getpid()) + "-" + std::to_string(++calls) + ".txt");
  run_all({{exe.string(), "--version"}}, {log}, 1);
  std::ifstream in(log);
  std::string first;
  std::getline(in, first);
  std::error_code ec;
  fs::remove(log, ec);
  return known[exe.string()] = exe.string() + " | " + first;
}

fs::path default_robot_cache_dir() {
  if (!env("SYMORO_CACHE_DIR").empty()) return env("SYMORO_CACHE_DIR");
  if (!env("XDG_CACHE_HOME").empty()) return fs::path(env("XDG_CACHE_HOME")) / "symoro/robots";
  if (!env("HOME").empty()) return fs::path(env("HOME")) / ".cache/symoro/robots";
  return fs::temp_directory_path() / "symoro-robots";
}

namespace {

// The digest of the generated code, then the cache key: that code, the ABI, compiler, flags and
// symoro's headers the units compile (the ABI, its export, the generated code's support).
struct CacheKey {
  std::string code_digest, build_line, key;
};
CacheKey cache_key(const Generation& gen, const RobotToolchain& tc) {
  std::vector<const GeneratedFile*> files;
  for (const auto& f : gen.files) files.push_back(&f);
  std::sort(files.begin(), files.end(), [](const auto* a, const auto* b) { return a->path < b->path; });
  std::string all;
  for (const auto* f : files) all += f->path + '\0' + f->content + '\0';
  CacheKey k;
  k.code_digest = hex128(all);
  k.build_line = tc.identity() + " | " + joined(tc.flags);
  std::string key_text = "symoro robot library abi " + std::to_string(SYMORO_ROBOT_ABI_VERSION) + '\0' + k.code_digest +
                         '\0' + k.build_line;
  for (const auto& d : tc.include_dirs) {
    key_text += '\0' + d;
    for (const char* h : {SYMORO_ROBOT_ABI_HEADERS}) {
      std::ifstream in(fs::path(d) / "symoro" / h, std::ios::binary);
      if (in) key_text += '\0' + std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    }
  }
  k.key = hex128(key_text).substr(0, 20);
  return k;
}

// The units of a robot library, written into its build folder `work`, each with its compile
// command, its log and its object.
struct LibraryUnits {
  fs::path work, exe;
  const RobotToolchain* tc = nullptr;
  std::vector<std::vector<std::string>> compiles;
  std::vector<fs::path> logs, objects;

  void add(const std::string& name, const std::string& text) {
    const fs::path unit = work / "src" / (name + ".cpp");
    write_file(unit, text);
    objects.push_back(work / "src" / (name + ".o"));
    logs.push_back(work / "src" / (name + ".log"));
    std::vector<std::string> c = {exe.string()};
    c.insert(c.end(), tc->flags.begin(), tc->flags.end());
    c.push_back("-I" + (work / "include").string());
    for (const auto& d : tc->include_dirs) c.push_back("-I" + d);
    c.insert(c.end(), {"-c", unit.string(), "-o", objects.back().string()});
    compiles.push_back(std::move(c));
  }
};

// Two units per model: its kernels in the C ABI, and its inertia second derivatives (Jets), half
// of the model's compile time, beside it. Adds to `declarations` and `entries` the model's entry
// point for the library's unit.
void add_model_units(LibraryUnits& units, const RobotModel& robot, const Generation& gen, std::string& declarations,
                     std::string& entries) {
  for (std::size_t i = 0; i < gen.models.size(); ++i) {
    const auto [header, type] = model_names(robot.name, gen.models[i].name);
    // Named after the robot: the objects of several robots link into one program (--objects).
    const std::string fn = "symoro_" + robot.name + "_model_" + std::to_string(i);
    units.add(fn, "// Written by symoroc build for robot " + robot.name + ": model " + gen.models[i].name +
                      " in the robot library's C ABI; do not edit.\n"
                      "#include \"symoro/robot_abi_export-inl.hpp\"\n#include \"" +
                      header +
                      "\"\n\n"
                      "// For a program that links these objects too (compiled_model<Model>()).\n"
                      "template symoro_abi_model symoro::abi_export::model_abi<" +
                      type +
                      ">();\n\n"
                      "symoro_abi_model " +
                      fn + "() { return symoro::abi_export::model_abi<" + type + ">(); }\n");
    declarations += "symoro_abi_model " + fn + "();\n";
    entries += "      " + fn + "(),\n";
    units.add(fn + "_d2", "// Written by symoroc build for robot " + robot.name + ": model " + gen.models[i].name +
                              "'s inertia second derivatives; do not edit.\n"
                              "#include \"symoro/robot_abi_second_derivatives-inl.hpp\"\n#include \"" +
                              header +
                              "\"\n\n"
                              "template void symoro::abi_export::inertia_second_derivatives<" +
                              type + ">(const double*, const double*, double*, double*, double*);\n");
  }
}

// The library's entry points (symoro/robot_abi.h): its ABI version and its robot's table.
void add_entry_unit(LibraryUnits& units, const RobotModel& robot, const Generation& gen, const CacheKey& key,
                    const std::string& declarations, const std::string& entries) {
  std::string sources;
  for (const auto& [name, digest] : robot.sources)
    sources += "    {" + c_string(name) + ", " + c_string(digest) + "},\n";
  const std::string identified = robot.spec.identified == "full" ? "" : robot.spec.identified;
  units.add("robot",
            "// Written by symoroc build for robot " + robot.name +
                ": the library's entry points (symoro/robot_abi.h); do not edit.\n"
                "#include \"symoro/robot_abi.h\"\n\n" +
                declarations + "\nnamespace {\nconst symoro_abi_source_file sources[] = {\n" + sources +
                "};\n}  // namespace\n\n"
                "extern \"C\" __attribute__((visibility(\"default\"))) unsigned symoro_robot_abi_version(void) {\n"
                "  return SYMORO_ROBOT_ABI_VERSION;\n}\n\n"
                "extern \"C\" __attribute__((visibility(\"default\"))) const symoro_abi_robot* symoro_robot(void) {\n"
                "  static const symoro_abi_model models[] = {\n" +
                entries +
                "  };\n"
                "  static const symoro_abi_robot robot = {SYMORO_ROBOT_ABI_VERSION, " +
                c_string(robot.name) + ", " + c_string(identified) + ", " + c_string(key.code_digest) + ", " +
                c_string(key.build_line) + ", " + std::to_string(gen.models.size()) + ", models, " +
                std::to_string(robot.sources.size()) + ", sources};\n  return &robot;\n}\n");
}

}  // namespace

RobotLibraryBuild build_robot_library(const fs::path& robot_dir, const RobotLibraryOptions& options) {
  using clock = std::chrono::steady_clock;
  const auto say = [&](const std::string& line) {
    if (options.progress) options.progress(line);
  };
  const auto t0 = clock::now();
  RobotModel robot = load_robot(robot_dir.string());
  const Generation gen = generate_robot(robot);
  RobotLibraryBuild out;
  out.robot = robot.name;
  out.models = static_cast<int>(gen.models.size());
  const RobotToolchain& tc = options.toolchain;
  const CacheKey key = cache_key(gen, tc);
  out.code_digest = key.code_digest;
  out.key = key.key;
  out.generate_seconds = std::chrono::duration<double>(clock::now() - t0).count();

  const fs::path cache = options.cache_dir.empty() ? default_robot_cache_dir() : options.cache_dir;
  const fs::path final_dir = cache / (robot.name + "-" + out.key);
  out.library = final_dir / ("lib" + robot.name + ".so");
  std::error_code ec;
  if (!options.force && fs::exists(out.library, ec)) {  // cached
    if (!options.objects.empty()) write_objects(final_dir, options);
    return out;
  }

  // Build in a folder of its own, then move it into place.
  fs::create_directories(cache, ec);
  if (ec) throw BuildError("cannot create the robot cache " + cache.string() + ": " + ec.message());
  const fs::path work = cache / (".build-" + robot.name + "-" + out.key + "-" + std::to_string(getpid()));
  fs::remove_all(work, ec);
  for (const auto& f : gen.files) {
    // generated paths are <robot>/include/symoro/...: keep the include/ part
    const std::string rel = f.path.substr(f.path.find('/') + 1);
    write_file(work / rel, f.content);
  }
  LibraryUnits units{work, resolve_compiler(tc.compiler), &tc, {}, {}, {}};
  std::string declarations, entries;
  add_model_units(units, robot, gen, declarations, entries);
  add_entry_unit(units, robot, gen, key, declarations, entries);

  const int jobs = options.jobs > 0 ? options.jobs : std::max(1u, std::thread::hardware_concurrency());
  say(robot.name + ": compiling " + std::to_string(gen.models.size()) + " model(s) with " + units.exe.string() +
      " into " + final_dir.string());
  const auto t1 = clock::now();
  try {
    run_all(units.compiles, units.logs, jobs);
    std::vector<std::string> link = {units.exe.string(), "-shared", "-o", (work / out.library.filename()).string()};
    for (const auto& o : units.objects) link.push_back(o.string());
    run_all({link}, {work / "link.log"}, 1);
  } catch (const BuildError& e) {
    throw BuildError("robot library for " + robot_dir.string() + ": " + e.what());
  }
  out.compile_seconds = std::chrono::duration<double>(clock::now() - t1).count();
  out.built = true;
  write_file(work / "build.txt", "robot: " + robot.name + "\nfolder: " + fs::absolute(robot_dir).string() +
                                     "\ncode digest: " + out.code_digest + "\nbuild: " + key.build_line + "\n");

  // Into place; when another process finished the same library first, keep its copy.
  fs::rename(work, final_dir, ec);
  if (ec) {
    fs::remove_all(work, ec);
    if (!fs::exists(out.library)) throw BuildError("cannot move the robot library into " + final_dir.string());
  }
  say(robot.name + ": built " + out.library.string() + " in " + std::to_string(out.compile_seconds) + " s");
  if (!options.objects.empty()) write_objects(final_dir, options);
  return out;
}

}  // namespace symoro::codegen
