// Loading the PCL module (pcl_module.hpp) into the binary that needs it.
#include <dlfcn.h>

#include "pcl_module.hpp"

namespace tomomap {

const PclIo& pclIo() {
  // Loaded once and never unloaded: PCL's and VTK's static state lives as long
  // as the process. A failed load throws and is tried again on the next call.
  static const PclIo& io = []() -> const PclIo& {
    const std::string what = std::string("reading PLY or ascii PCD files and writing PCD files need the module ") +
                             kPclIoModule + " (installed with tomomap)";
    void* module = ::dlopen(kPclIoModule, RTLD_NOW | RTLD_LOCAL);
    if (!module) throw InputError(what + ", which did not load: " + ::dlerror());
    const auto entry = reinterpret_cast<PclIoEntry>(::dlsym(module, kPclIoEntry));
    const PclIo* functions = entry ? entry(kPclIoVersion) : nullptr;
    if (!functions) throw InputError(what + "; the one found is from another version of tomomap");
    return *functions;
  }();
  return io;
}

}  // namespace tomomap
