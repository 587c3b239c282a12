#pragma once
// One rule for every output of every command (the main output, reports, heatmaps, dumps): it is
// never one of the inputs (the same file by any name: symbolic and hard links included), and no two
// outputs of one run are the same file. Commands check it before any work, so a refused run writes
// nothing.
#include <filesystem>
#include <span>
#include <string>

#include "matbake/result.hpp"

namespace matbake {

struct NamedOutput {
  std::filesystem::path path;  // empty: not asked for (skipped)
  std::string role;            // what it is, for the error: "heatmap", "texture b", "report"
};

// Whether `a` and `b` name one file: the same real path (links followed; either may not exist
// yet) or, when both exist, the same inode.
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b);

// Whether `path`'s real location (symbolic links in it followed; its last part may not exist yet)
// lies inside `folder`'s real location.
bool is_really_inside(const std::filesystem::path& folder, const std::filesystem::path& path);

// Errors (usage errors, naming the output): "is an input; matbake never overwrites its inputs",
// "is written twice (<role> and <role>)".
Status check_outputs(std::span<const NamedOutput> outputs, std::span<const std::filesystem::path> inputs);

}  // namespace matbake
