// `matbake inspect`'s tables for a terminal, made from its JSON.
#include <algorithm>
#include <cstdio>

#include "matbake/inspect.hpp"
#include "matbake/join.hpp"
#include "matbake/result.hpp"

namespace matbake::inspect {
namespace {
using Json = nlohmann::json;
using Rows = std::vector<std::vector<std::string>>;

// Columns left-aligned to their widest cell, two spaces apart; names from files escaped.
std::string table(const std::string& title, const Rows& rows) {
  if (rows.size() <= 1) return "";
  std::vector<std::size_t> width;
  for (const auto& row : rows) {
    width.resize(std::max(width.size(), row.size()));
    for (std::size_t c = 0; c < row.size(); ++c) width[c] = std::max(width[c], escape_control(row[c]).size());
  }
  std::string out = title + "\n";
  for (const auto& row : rows) {
    std::string line = " ";
    for (std::size_t c = 0; c < row.size(); ++c) {
      const std::string cell = escape_control(row[c]);
      line += " " + cell + (c + 1 < row.size() ? std::string(width[c] - cell.size() + 1, ' ') : "");
    }
    out += line + "\n";
  }
  return out;
}

std::string bytes_text(std::uint64_t bytes) {
  char text[32];
  if (bytes >= 1024 * 1024) {
    std::snprintf(text, sizeof text, "%.2f MiB", double(bytes) / (1024.0 * 1024.0));
  } else if (bytes >= 1024) {
    std::snprintf(text, sizeof text, "%.1f KiB", double(bytes) / 1024.0);
  } else {
    std::snprintf(text, sizeof text, "%llu B", static_cast<unsigned long long>(bytes));
  }
  return text;
}

std::string str(const Json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }

std::string list(const Json& array) {
  std::vector<std::string> items;
  for (const Json& v : array) items.push_back(str(v));
  return items.empty() ? "-" : join(items, ", ");
}

std::string size_text(const Json& s) { return str(s["width"]) + "x" + str(s["height"]); }

std::string gpu_text(const Json& gpu) {
  return bytes_text(gpu["rgba8"].get<std::uint64_t>()) + " / " + bytes_text(gpu["block_4x4"].get<std::uint64_t>());
}

std::string gltf_text(const Json& j) {
  std::string out = j["file"].get<std::string>() + " (glTF; generator: " + (j["generator"] == "" ? "-" : str(j["generator"])) + ")\n";
  if (!j["extensionsUsed"].empty()) out += "extensions used: " + list(j["extensionsUsed"]) + "\n";
  Rows scenes{{"#", "name", "default", "nodes", "placements", "triangles"}};
  for (const Json& s : j["scenes"]) {
    scenes.push_back({str(s["index"]), str(s["name"]), s["default"].get<bool>() ? "yes" : "", str(s["nodes"]), str(s["mesh_placements"]),
                      str(s["triangles"])});
  }
  Rows meshes{{"#", "name", "primitives", "triangles", "vertices", "compression", "quantized", "attributes"}};
  for (const Json& m : j["meshes"]) {
    std::vector<std::string> attributes;
    for (const auto& [name, format] : m["attributes"].items()) attributes.push_back(name + " " + str(format));
    meshes.push_back({str(m["index"]), str(m["name"]), str(m["primitives"]), str(m["triangles"]), str(m["vertices"]),
                      list(m["compression"]), list(m["quantized"]), join(attributes, ", ")});
  }
  Rows materials{{"#", "name", "workflow", "alpha", "slots", "extensions"}};
  for (const Json& m : j["materials"]) {
    std::vector<std::string> slots;
    for (const Json& s : m["slots"]) slots.push_back(str(s["slot"]).substr(str(s["slot"]).rfind('.') + 1) + ":" + str(s["texture"]));
    materials.push_back({str(m["index"]), str(m["name"]), str(m["workflow"]), str(m["alpha_mode"]), slots.empty() ? "-" : join(slots, ", "),
                         list(m["extensions"])});
  }
  Rows textures{{"#", "used as", "class", "image", "format", "codec", "size", "levels", "bytes", "GPU RGBA8 / BC7-ASTC"}};
  for (const Json& t : j["textures"]) {
    std::vector<std::string> uses, classes;
    for (const Json& u : t["used_by"]) {
      uses.push_back("material " + str(u["material"]) + " " + str(u["slot"]).substr(str(u["slot"]).rfind('.') + 1));
      if (std::find(classes.begin(), classes.end(), str(u["class"])) == classes.end()) classes.push_back(str(u["class"]));
    }
    for (const Json& s : t["sources"]) {
      textures.push_back({str(t["index"]), uses.empty() ? "(unused)" : join(uses, ", "), classes.empty() ? "-" : join(classes, ", "),
                          str(s["image"]), str(s["format"]), str(s["codec"]), size_text(s), str(s["levels"]),
                          bytes_text(s["bytes"].get<std::uint64_t>()), gpu_text(s["gpu_bytes"])});
    }
  }
  Rows images{{"#", "name", "stored", "format", "size", "bytes", "textures", "duplicate of"}};
  for (const Json& i : j["images"]) {
    images.push_back({str(i["index"]), str(i.value("uri", i["name"])), str(i["stored"]), str(i["format"]), size_text(i),
                      bytes_text(i["bytes"].get<std::uint64_t>()), list(i["textures"]),
                      i["duplicate_of"].is_null() ? "" : "image " + str(i["duplicate_of"])});
  }
  const Json& t = j["totals"];
  return out + table("scenes", scenes) + table("meshes", meshes) + table("materials", materials) + table("textures", textures) +
         table("images", images) + "totals: " + str(t["triangles"]) + " triangles in the default scene, " + str(t["vertices"]) +
         " vertices, images " + bytes_text(t["image_bytes"].get<std::uint64_t>()) + ", GPU " + gpu_text(t["gpu_bytes"]) +
         " (RGBA8 / BC7-ASTC 4x4)\n";
}

std::string ktx2_text(const Json& j) {
  const Json& h = j["header"];
  const Json& d = j["descriptor"];
  std::string out = j["file"].get<std::string>() + " (KTX2, " + bytes_text(j["bytes"].get<std::uint64_t>()) + ")\n";
  out += "  " + str(d["codec"]) + ", " + size_text(h) + ", " + str(h["levels"]) + " levels, supercompression " +
         str(h["supercompression"]) + ", vkFormat " + str(h["vk_format"]) + "\n";
  out += "  DFD: colour model " + str(d["color_model"]) + ", primaries " + str(d["primaries"]) + ", transfer " + str(d["transfer"]) +
         ", channels " + list(d["channels"]) + (d["alpha_premultiplied"].get<bool>() ? ", premultiplied alpha" : "") + "\n";
  out += "  GPU: " + gpu_text(j["gpu_bytes"]) + " (RGBA8 / BC7-ASTC 4x4)\n";
  Rows levels{{"level", "size", "bytes", "uncompressed"}};
  for (const Json& l : j["levels"]) {
    levels.push_back({str(l["level"]), size_text(l), bytes_text(l["bytes"].get<std::uint64_t>()),
                      bytes_text(l["uncompressed_bytes"].get<std::uint64_t>())});
  }
  Rows kv{{"key", "value"}};
  for (const auto& [key, value] : j["key_values"].items()) kv.push_back({key, str(value)});
  return out + table("levels", levels) + table("key/value data", kv);
}

// A scene's planned delivery: each texture's sizes, codec and estimated bytes, then the bytes per class.
std::string delivery_text(const Json& job) {
  const Json& d = job["delivery"];
  if (d.contains("error")) return str(job["name"]) + " cannot be planned: " + str(d["error"]) + "\n";
  Rows textures{{"#", "class", "materials", "source", "needed", "delivered", "codec", "levels", "estimated bytes"}};
  const auto size = [](const Json& s) { return str(s[0]) + "x" + str(s[1]); };
  for (const Json& t : d["textures"]) {
    textures.push_back({str(t["texture"]), str(t["class"]), list(t["materials"]), size(t["source_size"]),
                        t.contains("needed_side") ? str(t["needed_side"]) : "-", size(t["size"]), str(t["codec"]), str(t["levels"]),
                        bytes_text(t["estimated_bytes"].get<std::uint64_t>()) + (t.contains("note") ? " (" + str(t["note"]) + ")" : "")});
  }
  const Json& e = d["estimated_bytes"];
  return table(str(job["name"]) + ": textures as it would deliver them (estimated, docs/inspect.md)", textures) +
         "  estimated: colour " + bytes_text(e["colour"].get<std::uint64_t>()) + ", data " + bytes_text(e["data"].get<std::uint64_t>()) +
         ", normal " + bytes_text(e["normal"].get<std::uint64_t>()) + ", total " + bytes_text(e["total"].get<std::uint64_t>()) + "\n" +
         (d.contains("not_estimated") ? "  not estimated: " + str(d["not_estimated"]) + "\n" : "");
}

std::string manifest_text(const Json& j) {
  std::string out = j["file"].get<std::string>() + " (manifest; output " + str(j["output"]) + ")\n";
  Rows jobs{{"job", "state", "why", "writes"}};
  for (const Json& job : j["jobs"]) {
    const std::string state = str(job["state"]);
    const std::string why = state == "failed" ? str(job["error"]) : state == "out_of_date" ? str(job["reason"]) : "";
    jobs.push_back({str(job["name"]), state, why, std::to_string(job["outputs"].size()) + " files"});
  }
  const Json& c = j["counts"];
  out += table("jobs", jobs) + "up to date " + str(c["up_to_date"]) + ", out of date " + str(c["out_of_date"]) + ", failed " +
         str(c["failed"]) + "\n";
  for (const Json& job : j["jobs"]) {
    if (job.contains("delivery")) out += delivery_text(job);
  }
  return out;
}

}  // namespace

std::string text(const nlohmann::json& inspected) {
  const std::string kind = inspected.value("kind", "");
  if (kind == "gltf") return gltf_text(inspected);
  if (kind == "ktx2") return ktx2_text(inspected);
  return manifest_text(inspected);
}

}  // namespace matbake::inspect
