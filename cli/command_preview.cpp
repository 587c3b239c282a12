#include <nlohmann/json.hpp>

#include <fstream>
#include <sstream>

#include "commands.hpp"
#include "matbake/atomic_file.hpp"
#include "matbake/encoding_params.hpp"
#include "matbake/image.hpp"
#include "matbake/preview_params.hpp"
#include "matbake/shading_catalog.hpp"
#include "params_cli.hpp"

namespace fs = std::filesystem;

namespace matbake::cli {
namespace {

Result<std::vector<preview::Material>> materials_from(const PreviewSettings& s) {
  if (!s.materials.empty()) return preview::load_materials(s.materials);
  auto maps = gather_sources(s.sources);
  if (!maps) return maps.error();
  auto material = preview::material_from_maps("material", *maps);
  if (!material) return material.error();
  return std::vector<preview::Material>{std::move(*material)};
}

Status write_sidecar(const fs::path& path, const preview::Preview& result, const std::string& model) {
  nlohmann::json cells = nlohmann::json::array();
  for (const preview::Cell& c : result.cells) {
    const auto& m = c.material;
    cells.push_back({{"row", c.row}, {"column", c.column}, {"x", c.x}, {"y", c.y}, {"size", c.size},
                     {"name", m.name}, {"kd", {m.kd.x, m.kd.y, m.kd.z}}, {"ks", {m.ks.x, m.ks.y, m.ks.z}},
                     {"gloss", m.gloss}, {"exponent", shading::schuler_exponent(m.gloss)},
                     {"textured", m.textures != nullptr}});
  }
  const nlohmann::json doc = {{"model", model}, {"colour", "sRGB 8-bit"}, {"cells", cells}};
  auto file = AtomicFile::create(path);
  if (!file) return file.error();
  {
    std::ofstream out(file->temp_path());
    out << doc.dump(2) << "\n";
    if (!out) return Error{path.string(), "cannot write"};
  }
  return file->commit();
}

}  // namespace

CLI::App* setup_preview(CLI::App& app, PreviewSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "preview",
      "Render material balls (Schüler's two-hemisphere light plus two directional lights) to an sRGB PNG,\n"
      "with a JSON sidecar (OUT.json) naming each cell. Sources as for pack: constants (linear, in [0, 1]) or\n"
      "textures sampled at the ball's UV; Schüler's (--kd, --ks, --gloss, --mask; defaults 0.5, 0.04, 0.5) or\n"
      "metal-rough (--base-color, --metallic, --roughness), or a packed pair (--from schuler A.png B.png).");
  cmd->add_option("-o,--output", s.output, "Output .png")->required();
  add_source_options(*cmd, s.sources, {"transfer", "decode", "resize"});
  cmd->add_option("--materials", s.materials, "JSON list of materials, one row each (see docs/preview.md)");
  add_params(*cmd, preview::options_params(), s.options, "", "Options");
  add_params(*cmd, image::encoding_params(), s.encoding, "", "Options");
  return cmd;
}

int run_preview(const PreviewSettings& s, const GlobalOptions& global) {
  const fs::path output(s.output);
  if (output.extension() != ".png") return report_error(Error{s.output, "preview writes .png", true});
  auto materials = materials_from(s);
  if (!materials) return report_error(materials.error());
  auto result = preview::render(*materials, s.options);
  if (!result) return report_error(result.error());
  const image::WriteOptions png{color::Transfer::srgb, image::SampleType::u8, "", "sRGB", s.encoding.png_level};
  if (Status st = image::write_image(result->image, output, png); !st) return report_error(st.error());
  fs::path sidecar = output;
  sidecar.replace_extension(".json");
  if (Status st = write_sidecar(sidecar, *result, s.options.model); !st) return report_error(st.error());
  if (global.json) {
    std::cout << nlohmann::json{{"command", "preview"}, {"output", s.output}, {"sidecar", sidecar.string()},
                                {"cells", result->cells.size()}}.dump(2)
              << "\n";
  } else if (!global.quiet) {
    std::cout << s.output << " (" << result->image.width << "x" << result->image.height << ", "
              << result->cells.size() << " cells, " << s.options.model << ") and " << sidecar.string() << "\n";
  }
  return kOk;
}

}  // namespace matbake::cli
