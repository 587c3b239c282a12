#include <nlohmann/json.hpp>

#include <fstream>
#include <sstream>

#include "commands.hpp"
#include "matbake/atomic_file.hpp"
#include "matbake/image.hpp"
#include "matbake/shading_catalog.hpp"

namespace fs = std::filesystem;

namespace matbake::cli {
namespace {

// "0.5" (gray) or "0.9,0.6,0.2".
Result<shading::Vec3> parse_colour(const std::string& text, const char* option) {
  const auto values = parse_numbers(text);
  if (!values) return Error{"", std::string(option) + " '" + text + "' is not a number or r,g,b", true};
  if (values->size() == 1) return shading::Vec3((*values)[0]);
  if (values->size() == 3) return shading::Vec3((*values)[0], (*values)[1], (*values)[2]);
  return Error{"", std::string(option) + " '" + text + "' needs 1 or 3 values", true};
}

Result<std::vector<preview::Material>> materials_from(const PreviewSettings& s) {
  if (!s.materials.empty()) return preview::load_materials(s.materials);
  if (!s.base_color.empty()) {
    auto base = parse_colour(s.base_color, "--base-color");
    if (!base) return base.error();
    return std::vector<preview::Material>{preview::from_metal_rough("metal-rough", *base, s.metallic, s.roughness)};
  }
  auto kd = parse_colour(s.kd, "--kd");
  if (!kd) return kd.error();
  auto ks = parse_colour(s.ks, "--ks");
  if (!ks) return ks.error();
  return std::vector<preview::Material>{{"material", *kd, *ks, s.gloss}};
}

Status write_sidecar(const fs::path& path, const preview::Preview& result, const std::string& model) {
  nlohmann::json cells = nlohmann::json::array();
  for (const preview::Cell& c : result.cells) {
    const auto& m = c.material;
    cells.push_back({{"row", c.row}, {"column", c.column}, {"x", c.x}, {"y", c.y}, {"size", c.size},
                     {"name", m.name}, {"kd", {m.kd.x, m.kd.y, m.kd.z}}, {"ks", {m.ks.x, m.ks.y, m.ks.z}},
                     {"gloss", m.gloss}, {"exponent", shading::schuler_exponent(m.gloss)}});
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
  std::string model_names;
  for (const auto& m : shading::models()) model_names += (model_names.empty() ? "" : ", ") + std::string(m.name);
  CLI::App* cmd = app.add_subcommand(
      "preview",
      "Render material balls (Schüler's two-hemisphere light plus two directional lights) to an sRGB PNG,\n"
      "with a JSON sidecar (OUT.json) naming each cell. Colours are linear, in [0, 1].");
  cmd->add_option("-o,--output", s.output, "Output .png")->required();
  cmd->add_option("--kd", s.kd, "Diffuse colour: gray or r,g,b")->capture_default_str();
  cmd->add_option("--ks", s.ks, "Specular colour (F0): gray or r,g,b")->capture_default_str();
  cmd->add_option("--gloss", s.gloss, "Gloss g in [0, 1]; exponent e = 2^(12 g)")->capture_default_str();
  cmd->add_option("--base-color", s.base_color, "Metal-rough instead: base colour r,g,b (with --metallic, --roughness)");
  cmd->add_option("--metallic", s.metallic, "Metal-rough: metallic")->capture_default_str();
  cmd->add_option("--roughness", s.roughness, "Metal-rough: glTF roughness")->capture_default_str();
  cmd->add_option("--materials", s.materials, "JSON list of materials, one row each (see docs/preview.md)");
  cmd->add_option("--gloss-sweep", s.gloss_sweep, "Columns at these gloss values, e.g. 0.25,0.5,0.75,1")->delimiter(',');
  cmd->add_option("--model", s.model, "BRDF for the direct lights: " + model_names)->capture_default_str();
  cmd->add_option("--size", s.size, "Pixels per cell")->capture_default_str();
  return cmd;
}

int run_preview(const PreviewSettings& s, const GlobalOptions& global) {
  const fs::path output(s.output);
  if (output.extension() != ".png") return report_error(Error{s.output, "preview writes .png", true});
  auto materials = materials_from(s);
  if (!materials) return report_error(materials.error());
  preview::Options options;
  options.model = s.model;
  options.cell_size = s.size;
  options.glosses = s.gloss_sweep;
  auto result = preview::render(*materials, options);
  if (!result) return report_error(result.error());
  const image::WriteOptions png{color::Transfer::srgb, image::SampleType::u8, "", "sRGB"};
  if (Status st = image::write_image(result->image, output, png); !st) return report_error(st.error());
  fs::path sidecar = output;
  sidecar.replace_extension(".json");
  if (Status st = write_sidecar(sidecar, *result, s.model); !st) return report_error(st.error());
  if (global.json) {
    std::cout << nlohmann::json{{"command", "preview"}, {"output", s.output}, {"sidecar", sidecar.string()},
                                {"cells", result->cells.size()}}.dump(2)
              << "\n";
  } else if (!global.quiet) {
    std::cout << s.output << " (" << result->image.width << "x" << result->image.height << ", "
              << result->cells.size() << " cells, " << s.model << ") and " << sidecar.string() << "\n";
  }
  return kOk;
}

}  // namespace matbake::cli
