// load_robot's first stage: find the folder's files and parse them. Syntax errors are the
// grammar's ParseError; a missing or doubled file is an InputError on the folder.
#include <algorithm>
#include <filesystem>

#include "stages.hpp"
#include "symoro/codegen/robot_name.hpp"
#include "symoro/codegen/source_digest.hpp"
#include "symoro/grammar/parser.hpp"

namespace symoro::codegen::load {

namespace fs = std::filesystem;

namespace {

// The folder names the generated namespace, so it must be a C++ identifier.
void check_folder(const fs::path& dir, RobotModel& m) {
  m.dir = dir.string();
  m.name = (dir.has_filename() ? dir.filename() : dir.parent_path().filename()).string();
  if (const std::string why = robot_name_problem(m.name); !why.empty())
    throw InputError(m.dir, 0, 0, why + " (the folder's name)");
  if (!fs::is_directory(dir)) throw InputError(m.dir, 0, 0, "not a directory");
}

// <robot>.par and <robot>_base.par: exactly one of each, whatever <robot> is.
std::pair<std::string, std::string> find_par_files(const fs::path& dir, const RobotModel& m) {
  std::string par_path, base_par_path;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string file = entry.path().filename().string();
    if (entry.path().extension() != ".par") continue;
    std::string& slot =
        file.size() > 9 && file.compare(file.size() - 9, 9, "_base.par") == 0 ? base_par_path : par_path;
    if (!slot.empty())
      throw InputError(m.dir, 0, 0,
                       "more than one " + std::string(&slot == &par_path ? "robot" : "base") + " .par file");
    slot = entry.path().string();
  }
  if (par_path.empty()) throw InputError(m.dir, 0, 0, "no <robot>.par description");
  if (base_par_path.empty()) throw InputError(m.dir, 0, 0, "no <robot>_base.par description");
  return {par_path, base_par_path};
}

// The digests source.hpp carries, sorted by file name so that the order of the folder's listing
// does not matter.
void digest_sources(const fs::path& dir, const std::string& par_path, const std::string& base_par_path, RobotModel& m) {
  for (const std::string& f : {(dir / "robot.yaml").string(), par_path, base_par_path})
    m.sources.emplace_back(fs::path(f).filename().string(), file_content_digest(f));
  for (const char* f : {"dim.txt", "idm.txt", "ddm.txt", "inm.txt", "ccg.txt", "fgm.txt", "jac.txt", "regp.txt"})
    if (fs::exists(dir / f)) m.sources.emplace_back(f, file_content_digest((dir / f).string()));
  std::sort(m.sources.begin(), m.sources.end());
}

}  // namespace

RobotFiles read_robot_folder(const std::string& dir_in, RobotModel& m) {
  const fs::path dir = fs::path(dir_in).lexically_normal();
  check_folder(dir, m);
  m.spec = read_robot_spec((dir / "robot.yaml").string());
  const auto [par_path, base_par_path] = find_par_files(dir, m);
  digest_sources(dir, par_path, base_par_path, m);

  RobotFiles files;
  files.par_path = par_path;
  files.par = grammar::read_par_file(par_path);
  grammar::read_par_file(base_par_path);  // checked for syntax; the model files carry its content
  auto read = [&](const char* f) { return grammar::read_model_file((dir / f).string()); };
  files.dim = read("dim.txt");
  files.idm = read("idm.txt");
  files.ddm = read("ddm.txt");
  files.inm = read("inm.txt");
  files.ccg = read("ccg.txt");
  files.fgm = read("fgm.txt");
  files.jac = read("jac.txt");
  files.regp = read("regp.txt");
  return files;
}

}  // namespace symoro::codegen::load
