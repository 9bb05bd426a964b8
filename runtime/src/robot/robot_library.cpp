#include "symoro/robot/robot_library.hpp"

#include <dlfcn.h>

#include <map>
#include <mutex>

#include "symoro/io/digest.hpp"

namespace symoro::robot {
namespace fs = std::filesystem;

namespace {

// Libraries stay loaded for the process: handles and function pointers never dangle.
std::mutex registry_mutex;
std::map<std::string, std::shared_ptr<const RobotLibrary>>& registry() {
  static std::map<std::string, std::shared_ptr<const RobotLibrary>> libraries;
  return libraries;
}

}  // namespace

RobotLibrary::RobotLibrary(fs::path path, const symoro_abi_robot* abi)
    : path_(std::move(path)),
      abi_(abi),
      robot_(abi->robot ? abi->robot : ""),
      code_digest_(abi->code_digest ? abi->code_digest : "") {}

std::shared_ptr<const RobotLibrary> RobotLibrary::open(const fs::path& library) {
  std::error_code ec;
  const fs::path canonical = fs::canonical(library, ec);
  if (ec) throw LoadError("robot library " + library.string() + ": " + ec.message());
  const std::lock_guard<std::mutex> lock(registry_mutex);
  auto& libraries = registry();
  if (const auto it = libraries.find(canonical.string()); it != libraries.end()) return it->second;

  // RTLD_LOCAL: two robots' libraries never resolve each other's symbols.
  void* handle = dlopen(canonical.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) throw LoadError("robot library " + canonical.string() + ": cannot load it: " + dlerror());
  const auto version = reinterpret_cast<symoro_robot_abi_version_fn>(dlsym(handle, "symoro_robot_abi_version"));
  const auto entry = reinterpret_cast<symoro_robot_fn>(dlsym(handle, "symoro_robot"));
  if (!version || !entry) {
    dlclose(handle);
    throw LoadError("robot library " + canonical.string() +
                    ": not a symoro robot library (no symoro_robot_abi_version or symoro_robot); build one with "
                    "symoroc build robots/<name>");
  }
  const unsigned v = version();
  if (v != SYMORO_ROBOT_ABI_VERSION) {
    dlclose(handle);
    throw LoadError("robot library " + canonical.string() + ": ABI version " + std::to_string(v) +
                    ", this symoro reads ABI version " + std::to_string(SYMORO_ROBOT_ABI_VERSION) +
                    ": rebuild it with this symoro (symoroc build <robot folder> --force)");
  }
  const symoro_abi_robot* abi = entry();
  if (!abi || abi->abi_version != SYMORO_ROBOT_ABI_VERSION || abi->n_models < 1 || !abi->models)
    throw LoadError("robot library " + canonical.string() + ": its description is malformed");
  auto lib = std::make_shared<const RobotLibrary>(canonical, abi);
  libraries.emplace(canonical.string(), lib);
  return lib;
}

void RobotLibrary::check_folder(const fs::path& robot_dir) const {
  if (!fs::is_directory(robot_dir))
    throw LoadError("robot '" + robot_ + "': " + robot_dir.string() + " is not a folder");
  for (int i = 0; i < abi_->n_sources; ++i) {
    const symoro_abi_source_file& f = abi_->sources[i];
    const fs::path file = robot_dir / f.name;
    if (!fs::exists(file))
      throw LoadError(file.string() + " is missing: the robot library " + path_.string() +
                      " was compiled from a folder "
                      "that has it");
    const std::string now = io::file_digest(file);
    if (now != f.digest)
      throw LoadError(file.string() + " differs from the " + f.name + " the robot library " + path_.string() +
                      " was compiled from (digest " + now + ", library " + f.digest +
                      "): build the folder's own library (symoroc build " + robot_dir.string() + ")");
  }
}

std::vector<std::string> RobotLibrary::model_labels() const {
  std::vector<std::string> out;
  for (int i = 0; i < abi_->n_models; ++i) {
    const std::string v = abi_->models[i].variant ? abi_->models[i].variant : "";
    out.push_back(v.empty() ? "full" : v);
  }
  return out;
}

ModelHandle RobotLibrary::model(int index) const {
  if (index < 0 || index >= abi_->n_models)
    throw LoadError("robot '" + robot_ + "' has " + std::to_string(abi_->n_models) + " models, not model " +
                    std::to_string(index));
  return ModelHandle(shared_from_this(), &abi_->models[index]);
}

ModelHandle RobotLibrary::model(const std::string& label) const {
  const std::string want = label.empty() ? (abi_->identified && *abi_->identified ? abi_->identified : "full") : label;
  const auto labels = model_labels();
  std::string list;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (labels[i] == want) return model(static_cast<int>(i));
    list += (list.empty() ? "" : ", ") + labels[i];
  }
  throw LoadError("robot '" + robot_ + "' has no model '" + want + "' (it has: " + list + ")");
}

}  // namespace symoro::robot
