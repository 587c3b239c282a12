#include "ao_options.hpp"


#include <cstdio>

namespace matbake::cli {

void add_dump_texture(CLI::App& cmd, std::string& folder, const std::string& prefix, const std::string& help_group) {
  cmd.add_option("--" + prefix + "dump-texture", folder,
                 "Also write each texture as float EXR into this folder (with --" + prefix + "texture)")
      ->group(help_group);
}

Status set_dump_texture(ao::Request& request, const std::string& folder, const std::string& prefix) {
  if (folder.empty()) return success();
  if (!request.texture) return Error{"--" + prefix + "dump-texture", "applies only with --" + prefix + "texture as well", true};
  request.texture->dump = folder;
  return success();
}

void print_texture_reports(const std::vector<bake_ao::TextureReport>& textures) {
  for (const bake_ao::TextureReport& t : textures) {
    const double mapped = double(t.covered + t.touched);
    if (t.node >= 0) std::printf("node %d, ", t.node);
    std::printf("material %d '%s': %s, %dx%d over TEXCOORD_%d, %zu texels mapped (%zu on seams), %.1f%% of them overlapped, "
                "%zu padded, mean %.4f%s\n",
                t.material, escape_control(t.name).c_str(), t.file.c_str(), t.width, t.height, t.texcoord, t.covered + t.touched, t.touched,
                mapped > 0 ? 100.0 * double(t.overlapped) / mapped : 0.0, t.padded, t.mean,
                t.existing.empty() ? "" : (", its own occlusion texture " + t.existing).c_str());
    if (!t.orm.empty()) std::printf("  ORM %s\n", t.orm.c_str());
    if (t.wrapped) std::printf("  %zu triangles reach outside [0, 1]: wrapped by the sampler's mode\n", t.wrapped);
    if (t.degenerate_uv) std::printf("  %zu triangles with no UV area skipped\n", t.degenerate_uv);
    if (t.too_large) std::printf("  %zu triangles spanning more than 64 copies of the texture skipped\n", t.too_large);
    if (t.instances_without_uv) {
      std::printf("  %zu placed primitives lack TEXCOORD_%d: skipped (per-vertex AO can still be baked)\n",
                  t.instances_without_uv, t.texcoord);
    }
  }
}

}  // namespace matbake::cli
