// An LD_PRELOAD shim for one race test: a rename onto a file named owner.json waits 300 ms first, so
// that manifests started together all reach the output folder's ownership check while the first has
// not yet recorded itself (the window a fast machine hides).
#include <dlfcn.h>
#include <unistd.h>

#include <cstring>

extern "C" int rename(const char* from, const char* to) {
  using Rename = int (*)(const char*, const char*);
  static const Rename real = reinterpret_cast<Rename>(::dlsym(RTLD_NEXT, "rename"));
  constexpr const char kOwner[] = "owner.json";
  const std::size_t n = std::strlen(to), m = sizeof kOwner - 1;
  if (n >= m && std::strcmp(to + n - m, kOwner) == 0) ::usleep(300000);
  return real(from, to);
}
