#include <bit>
#include <cstdio>
#include <fstream>

#include "matbake/ao.hpp"
#include "matbake/atomic_file.hpp"

namespace matbake::ao {

Status write_dump(const std::filesystem::path& path, const scene::Scene& scene, const Bake& bake) {
  const std::string ext = path.extension().string();
  if (ext != ".csv" && ext != ".bin") return Error{path.string(), "the dump is .csv or .bin", true};
  static_assert(std::endian::native == std::endian::little, "the .bin dump is written little-endian as is");
  auto file = AtomicFile::create(path);
  if (!file) return file.error();
  {
    std::ofstream out(file->temp_path(), std::ios::binary);
    if (ext == ".csv") out << "node,mesh,primitive,vertex,x,y,z,ao\n";
    for (std::size_t k = 0; k < scene.instances.size(); ++k) {
      const scene::Instance& inst = scene.instances[k];
      const std::vector<float>& values = bake.values[k];
      if (ext == ".bin") {
        out.write(reinterpret_cast<const char*>(values.data()), std::streamsize(values.size() * sizeof(float)));
        continue;
      }
      for (std::size_t v = 0; v < values.size(); ++v) {
        char line[200];
        const scene::Vec3& p = inst.positions[v];
        // %.9g: every float comes back exactly.
        std::snprintf(line, sizeof line, "%d,%d,%d,%zu,%.9g,%.9g,%.9g,%.9g\n", inst.node, inst.mesh, inst.primitive, v,
                      double(p.x), double(p.y), double(p.z), double(values[v]));
        out << line;
      }
    }
    if (!out) return Error{path.string(), "cannot write"};
  }
  return file->commit();
}

}  // namespace matbake::ao
