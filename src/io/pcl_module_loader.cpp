// Loading the PCL module (pcl_module.hpp) into the binary that needs it.
#include <dlfcn.h>

#include <vector>

#include "pcl_module.hpp"

namespace tomomap {
namespace {

/// The folders the program's own RUNPATH names, then the system's, as the
/// dynamic linker would search them for the program (RTLD_DI_SERINFO). Asked
/// of the program rather than left to dlopen, which searches the RUNPATH of
/// its caller: under AddressSanitizer that caller is the sanitizer's library.
std::vector<std::string> programSearchPath() {
  void* program = ::dlopen(nullptr, RTLD_LAZY);
  Dl_serinfo size{};
  if (!program || ::dlinfo(program, RTLD_DI_SERINFOSIZE, &size) != 0) return {};
  std::vector<char> buffer(size.dls_size);
  auto* info = reinterpret_cast<Dl_serinfo*>(buffer.data());
  if (::dlinfo(program, RTLD_DI_SERINFOSIZE, info) != 0 || ::dlinfo(program, RTLD_DI_SERINFO, info) != 0) return {};
  std::vector<std::string> folders;
  for (unsigned i = 0; i < info->dls_cnt; ++i)
    if (info->dls_serpath[i].dls_name[0] == '/') folders.emplace_back(info->dls_serpath[i].dls_name);
  return folders;  // relative entries (the working folder) are never searched
}

const PclIo& loadPclIo() {
  const std::string what = std::string("reading PLY or ascii PCD files and writing PCD files need the module ") +
                           kPclIoModule + " (installed with tomomap)";
  std::string error = "not found beside the program";
  for (const std::string& folder : programSearchPath()) {
    const std::string path = folder + "/" + kPclIoModule;
    void* module = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!module) {
      if (const char* e = ::dlerror(); e && std::string(e).find("No such file") == std::string::npos) error = e;
      continue;
    }
    const auto entry = reinterpret_cast<PclIoEntry>(::dlsym(module, kPclIoEntry));
    if (const PclIo* functions = entry ? entry(kPclIoVersion) : nullptr) return *functions;
    throw InputError(what + "; the one in " + folder + " is from another version of tomomap");
  }
  throw InputError(what + ", which did not load: " + error);
}

}  // namespace

const PclIo& pclIo() {
  // Loaded once and never unloaded: PCL's and VTK's static state lives as long
  // as the process. A failed load throws and is tried again on the next call.
  static const PclIo& io = loadPclIo();
  return io;
}

}  // namespace tomomap
