// The README's and docs/'s examples are what a new user copies first: every ```toml block is
// valid TOML and every ```json block valid JSON (docs/build.md's rule example was an inline table
// over several lines, which TOML forbids), and every relative link resolves.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace matbake::test {
namespace {

namespace fs = std::filesystem;

struct Block {
  std::string language;
  std::string text;
  int line = 0;  // of the opening fence
};

std::vector<fs::path> markdown_files() {
  const fs::path root(MATBAKE_SOURCE_DIR);
  std::vector<fs::path> files = {root / "README.md"};
  for (const auto& entry : fs::directory_iterator(root / "docs")) {
    if (entry.path().extension() == ".md") files.push_back(entry.path());
  }
  return files;
}

std::vector<Block> fenced_blocks(const fs::path& file) {
  std::ifstream in(file);
  std::vector<Block> blocks;
  std::string line;
  std::optional<Block> open;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.rfind("```", 0) == 0) {
      if (open) {
        blocks.push_back(*open);
        open.reset();
      } else {
        open = Block{line.substr(3), "", number};
      }
    } else if (open) {
      open->text += line + "\n";
    }
  }
  return blocks;
}

TEST(DocsExamples, EveryTomlAndJsonBlockParses) {
  int toml_blocks = 0, json_blocks = 0;
  for (const fs::path& file : markdown_files()) {
    for (const Block& block : fenced_blocks(file)) {
      const std::string where = file.filename().string() + ":" + std::to_string(block.line);
      if (block.language == "toml") {
        ++toml_blocks;
        try {
          const toml::table parsed = toml::parse(block.text);
          EXPECT_FALSE(parsed.empty()) << where;
        } catch (const toml::parse_error& e) {
          ADD_FAILURE() << where << ": not valid TOML: " << e.description() << " at line "
                        << e.source().begin.line << " of the block";
        }
      } else if (block.language == "json") {
        ++json_blocks;
        EXPECT_FALSE(nlohmann::json::parse(block.text, nullptr, false).is_discarded()) << where << ": not valid JSON";
      }
    }
  }
  EXPECT_GE(toml_blocks, 1);
  EXPECT_GE(json_blocks, 1);
}

// Links such as [build](build.md) or [x](../README.md#anchor): the file they name exists.
TEST(DocsExamples, EveryRelativeLinkResolves) {
  for (const fs::path& file : markdown_files()) {
    std::ifstream in(file);
    std::stringstream text;
    text << in.rdbuf();
    const std::string s = text.str();
    for (std::size_t at = s.find("]("); at != std::string::npos; at = s.find("](", at + 2)) {
      const std::size_t end = s.find(')', at + 2);
      if (end == std::string::npos) break;
      std::string target = s.substr(at + 2, end - at - 2);
      if (target.find("://") != std::string::npos || target.rfind("mailto:", 0) == 0 || target.empty() ||
          target[0] == '#') {
        continue;
      }
      target = target.substr(0, target.find('#'));
      EXPECT_TRUE(fs::exists(file.parent_path() / target)) << file.filename().string() << " links to " << target;
    }
  }
}

}  // namespace
}  // namespace matbake::test
