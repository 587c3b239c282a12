#include "oiio_module.hpp"

#include <dlfcn.h>

#include <atomic>
#include <stdexcept>

namespace matbake::image {
namespace {

std::atomic<int> g_threads{0};
std::atomic<const OiioCodecs*> g_loaded{nullptr};

struct Loaded {
  const OiioCodecs* codecs = nullptr;
  std::string error;
};

// The module sits beside libmatbake, in the build tree and once installed.
std::filesystem::path module_path() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<const void*>(&oiio_codecs), &info) == 0 || info.dli_fname == nullptr) {
    return "libmatbake_oiio.so";
  }
  return std::filesystem::path(info.dli_fname).parent_path() / "libmatbake_oiio.so";
}

Loaded load() {
  const std::filesystem::path path = module_path();
  // RTLD_LOCAL: OIIO's symbols stay out of the global scope, so libmatbake's override of OIIO's
  // ICC decoder (oiio_icc_override.cpp) still comes first for OIIO's own calls.
  void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* why = dlerror();
    return {nullptr, "cannot load matbake's OpenImageIO module: " + std::string(why ? why : path.string())};
  }
  auto entry = reinterpret_cast<const OiioCodecs* (*)()>(dlsym(handle, "matbake_oiio_codecs"));
  if (entry == nullptr) return {nullptr, path.string() + " is not matbake's OpenImageIO module"};
  const OiioCodecs* codecs = entry();
  // After g_loaded is set, set_thread_count applies to the module itself; before, this does.
  g_loaded = codecs;
  codecs->set_thread_count(g_threads);
  return {codecs, {}};
}

}  // namespace

Result<const OiioCodecs*> oiio_codecs(const std::string& user) {
  static const Loaded loaded = load();  // once, thread-safe; never unloaded
  if (loaded.codecs == nullptr) return Error{user, loaded.error};
  return loaded.codecs;
}

Image resize_image(const Image& image, int width, int height) {
  auto oiio = oiio_codecs("resize");
  if (!oiio) throw std::runtime_error(oiio.error().message);  // turned into one error line by the caller's guard
  return (*oiio)->resize(image, width, height);
}

void set_thread_count(int threads) {
  g_threads = threads;
  if (const OiioCodecs* codecs = g_loaded) codecs->set_thread_count(threads);  // else when it loads
}

}  // namespace matbake::image
