#pragma once
// The material table (presets/materials.toml, compiled in): F0 of real materials with their
// class and source, and the F0 classes validation sorts texels into.
#include <glm/vec3.hpp>

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "matbake/result.hpp"

namespace matbake::material_table {

using Vec3 = glm::dvec3;

enum class MaterialClass { dielectric, gem, semiconductor, metal };
std::string_view class_name(MaterialClass c);

struct Material {
  std::string name;
  MaterialClass material_class = MaterialClass::dielectric;
  Vec3 f0{0};                                    // linear RGB: what validation compares with
  std::optional<std::array<double, 2>> f0_range;  // as printed (Table 2.5.1)
  std::vector<int> table_code;                    // Schüler's 8-bit grey level or colour, as printed
  std::optional<double> ior;                      // dielectrics
  std::optional<Vec3> ior_n, ior_k;               // metals: complex index per channel
  std::string source;
};

// The shipped table.
const std::vector<Material>& builtin_table();
// A table file in the same format (errors name the file and the entry).
Result<std::vector<Material>> load_table(const std::filesystem::path& path);
Result<std::vector<Material>> parse_table(std::string_view toml_text, const std::string& origin);
const Material* find(const std::vector<Material>& table, std::string_view name);
// Names within a small edit distance of `name` (for "unknown material" errors), nearest first.
std::vector<std::string> near_names(const std::vector<Material>& table, std::string_view name);
// The entry named `name`, or an error listing near names.
Result<const Material*> lookup(const std::vector<Material>& table, std::string_view name);
// The table in `path`, or the built-in one when `path` is empty.
Result<std::vector<Material>> table_or_builtin(const std::filesystem::path& path);

// --- F0 classes (Schüler's table; validation) ---------------------------------------------------
// F0 < 0.02: below any real material; [0.02, 0.08): dielectric; [0.08, 0.2): gem;
// [0.2, 0.45): the semiconductor gap (rare); ≥ 0.45: metal. On the mean of the RGB channels.
inline constexpr double kBelowReal = 0.02, kGemFrom = 0.08, kSemiconductorFrom = 0.2, kMetalFrom = 0.45;
enum class F0Class { below, dielectric, gem, semiconductor, metal };
std::string_view f0_class_name(F0Class c);
inline F0Class classify_f0(double f0) {
  return f0 < kBelowReal       ? F0Class::below
         : f0 < kGemFrom        ? F0Class::dielectric
         : f0 < kSemiconductorFrom ? F0Class::gem
         : f0 < kMetalFrom      ? F0Class::semiconductor
                                : F0Class::metal;
}

}  // namespace matbake::material_table
