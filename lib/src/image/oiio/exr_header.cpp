#include "exr_header.hpp"

#include <OpenEXR/openexr.h>

#include <cstring>

namespace matbake::image {
namespace {

constexpr unsigned char kMagic[4] = {0x76, 0x2f, 0x31, 0x01};

struct Source {
  OIIO::Filesystem::IOProxy* file;
  std::string first_error;
};

int64_t read_at(exr_const_context_t, void* user, void* buffer, uint64_t size, uint64_t offset,
                exr_stream_error_func_ptr_t) {
  return int64_t(static_cast<Source*>(user)->file->pread(buffer, size, int64_t(offset)));
}

int64_t size_of(exr_const_context_t, void* user) { return int64_t(static_cast<Source*>(user)->file->size()); }

void keep_first_error(exr_const_context_t context, exr_result_t, const char* message) {
  void* user = nullptr;
  if (exr_get_user_data(context, &user) == EXR_ERR_SUCCESS && user != nullptr) {
    auto* source = static_cast<Source*>(user);
    if (source->first_error.empty()) source->first_error = message;
  }
}

}  // namespace

std::optional<std::string> exr_header_problem(OIIO::Filesystem::IOProxy& file) {
  unsigned char start[sizeof kMagic];
  if (file.pread(start, sizeof start, 0) != sizeof start || std::memcmp(start, kMagic, sizeof kMagic) != 0) {
    return std::nullopt;
  }
  Source source{&file, {}};
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.user_data = &source;
  init.read_fn = read_at;
  init.size_fn = size_of;
  init.error_handler_fn = keep_first_error;
  init.flags = EXR_CONTEXT_FLAG_STRICT_HEADER;
  exr_context_t context = nullptr;
  const exr_result_t result = exr_start_read(&context, "image", &init);  // a name is required; messages do not show it
  exr_finish(&context);
  if (result == EXR_ERR_SUCCESS) return std::nullopt;
  return source.first_error.empty() ? std::string(exr_get_default_error_message(result)) : source.first_error;
}

}  // namespace matbake::image
