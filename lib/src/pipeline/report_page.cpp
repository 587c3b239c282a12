// `build --report`: one HTML page of a build (docs/build.md#the-report-page), from this run's job
// reports and, for jobs that were up to date, the summaries their stamps recorded. The page links
// the output folder's own images relative to itself and copies each scene's PNG images (its AO
// textures among them) into report/SCENE/ beside it; no script, nothing from the network. Every
// text from a file (a stamp, a glTF) is escaped; image paths come from the plan, or are names made
// file-safe.
#include <cstdio>
#include <functional>
#include <map>
#include <set>

#include "../gltf/document.hpp"
#include "matbake/atomic_file.hpp"
#include "matbake/output_check.hpp"
#include "matbake/pipeline.hpp"
#include "state.hpp"

namespace matbake::pipeline {
namespace fs = std::filesystem;
using nlohmann::json;
namespace {

std::string html(std::string_view text) {
  std::string out;
  for (const char c : escape_control(text)) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

// A path relative to the page's folder, as a URL path (each part percent-encoded where needed).
std::string href(const fs::path& file, const fs::path& page_folder) {
  std::string out;
  for (const unsigned char c : file.lexically_relative(page_folder).generic_string()) {
    if (std::isalnum(c) || c == '/' || c == '.' || c == '-' || c == '_') {
      out += char(c);
    } else {
      char hex[4];
      std::snprintf(hex, sizeof hex, "%%%02X", c);
      out += hex;
    }
  }
  return out;
}

// A recorded summary is outside input (anyone may edit a stamp): a member of a value that is no
// object, or of another JSON type than the page shows, reads as absent.
json member(const json& j, const char* key) { return j.is_object() && j.contains(key) ? j[key] : json(); }
std::string text_in(const json& j, const char* key) {
  const json m = member(j, key);
  return m.is_string() ? m.get<std::string>() : std::string();
}

std::string file_safe(const std::string& name) {
  std::string out;
  for (const char c : name) out += std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' ? c : '_';
  return out.empty() ? "image" : out;
}

std::string number(const json& v, const char* format = "%.4g") {
  if (!v.is_number()) return "-";
  char text[32];
  std::snprintf(text, sizeof text, format, v.get<double>());
  return text;
}

// A texture's numbers per level (docs/build.md#the-report-page): each KTX2 level's PSNR as a GPU is
// given it, a normal map's mean / max angle, a MASK texture's coverage made and decoded.
std::string per_level(const json& texture) {
  const auto row = [&](const std::string& label, const json& values, const std::function<std::string(const json&)>& text) {
    if (!values.is_array() || values.empty()) return std::string();
    // Appended, not `"<div>" + html(label)`: GCC 12 at -O3 misreads that operator+ as a memcpy of
    // more than PTRDIFF_MAX bytes (-Wstringop-overflow) and the release build fails with -Werror.
    std::string line = "<div>";
    line += html(label);
    line += ':';
    for (const json& v : values) {
      line += ' ';
      line += text(v);
    }
    line += "</div>";
    return line;
  };
  const json& errors = member(texture, "level_error");
  const auto field = [](const char* key, const char* format) {
    return [=](const json& level) { return level.is_object() ? number(member(level, key), format) : std::string("-"); };
  };
  std::string out = row("PSNR (dB)", errors, field("psnr", "%.1f"));
  if (text_in(texture, "class") == "normal") {
    out += row("angle mean (°)", errors, field("mean_angle", "%.2f")) + row("angle max (°)", errors, field("max_angle", "%.1f"));
  }
  const json& coverage = member(texture, "coverage");
  out += row("coverage made (source first)", coverage, [](const json& c) { return number(c, "%.3f"); });
  if (texture.contains("alpha_cutoff")) out += row("coverage decoded", errors, field("coverage", "%.3f"));
  return out;
}

std::string figure(const std::string& src, const std::string& caption) {
  return "<figure><img src=\"" + src + "\" alt=\"" + html(caption) + "\"><figcaption>" + html(caption) + "</figcaption></figure>";
}

// What the page says of one job: this run's report, or its stamp's summary.
struct JobView {
  const Job* job = nullptr;
  std::string outcome;
  std::string reason;
  std::string error;
  double seconds = 0;
  json details;
  std::vector<std::string> warnings;
};

std::vector<JobView> job_views(const Report& report, const StampRoots& roots) {
  std::vector<JobView> views;
  for (const JobReport& r : report.jobs) {
    JobView v{r.job, std::string(name_in(kOutcomeNames, r.outcome)), r.reason, r.error ? r.error->to_string() : "", r.seconds,
              r.details, r.warnings};
    if (r.outcome == Outcome::up_to_date) {
      if (auto summary = recorded_summary(r.job->name, roots)) {
        v.seconds = summary->seconds, v.details = summary->details, v.warnings = summary->warnings;
      }
    } else if (r.outcome != Outcome::built && !r.error) {
      if (auto failure = recorded_failure(r.job->name, roots)) v.error = *failure;
    }
    if (!v.details.is_object()) v.details = json::object();
    views.push_back(std::move(v));
  }
  return views;
}

std::string jobs_table(const std::vector<JobView>& views) {
  std::string out = "<h2 id=\"jobs\">Jobs</h2><table><tr><th>job</th><th>this run</th><th>why</th><th>time (s)</th><th>error</th></tr>";
  for (const JobView& v : views) {
    out += "<tr class=\"" + v.outcome + "\"><td>" + html(v.job->name) + "</td><td>" + v.outcome + "</td><td>" + html(v.reason) +
           "</td><td>" + number(v.seconds, "%.2f") + "</td><td>" + html(v.error) + "</td></tr>";
  }
  return out + "</table>";
}

std::string conversion_table(const json& conversion) {
  if (!conversion.is_object() || !conversion.contains("errors") || !conversion["errors"].is_object()) return "";
  std::string out = "<p>" + html(text_in(conversion, "direction")) + ", mapping " + html(text_in(conversion, "mapping")) +
                    "</p><table><tr><th>error</th><th>mean</th><th>max</th><th>Khronos converter mean</th></tr>";
  const json& khronos = member(conversion, "khronos_converter_errors");
  for (const auto& [name, e] : conversion["errors"].items()) {
    if (!e.is_object()) continue;
    const json k = khronos.is_object() && khronos.contains(name) && khronos[name].is_object() ? khronos[name] : json::object();
    out += "<tr><td>" + html(name) + "</td><td>" + number(member(e, "mean")) + "</td><td>" + number(member(e, "max")) +
           "</td><td>" + number(member(k, "mean")) + "</td></tr>";
  }
  return out + "</table>";
}

std::string material_section(const JobView& v, const fs::path& page_folder) {
  const std::string name = v.job->name.substr(v.job->name.find(':') + 1);
  std::string out = "<section id=\"" + html(v.job->name) + "\"><h3>" + html(name) + "</h3><div class=\"figures\">";
  if (!v.job->outputs.preview.empty() && fs::exists(v.job->outputs.preview)) {
    out += figure(href(v.job->outputs.preview, page_folder), "preview");
  }
  for (const fs::path& t : v.job->outputs.textures) {
    if (fs::exists(t)) out += figure(href(t, page_folder), t.filename().string());
  }
  if (!v.job->outputs.heatmap.empty() && fs::exists(v.job->outputs.heatmap)) {
    out += figure(href(v.job->outputs.heatmap, page_folder), "validation heatmap");
  }
  out += "</div>";
  const json& validation = member(v.details, "validation");
  if (validation.is_object() && validation.contains("checked")) {
    const json& fraction = member(validation, "violation_fraction");
    out += "<p>validation: " + number(member(validation, "violations"), "%.0f") + " of " +
           number(member(validation, "checked"), "%.0f") + " texels flagged (" +
           number(fraction.is_number() ? json(100 * fraction.get<double>()) : json(), "%.3g") + "%), " +
           (member(validation, "passed") == true ? "passed" : "over the limit") + "</p>";
  }
  out += conversion_table(member(v.details, "conversion"));
  for (const std::string& w : v.warnings) out += "<p class=\"warning\">" + html(w) + "</p>";
  if (!v.error.empty()) out += "<p class=\"error\">" + html(v.error) + "</p>";
  return out + "</section>";
}

// `base`, else base-2, base-3, ...: the first name `used` does not hold yet (now held). Names that
// file_safe makes one (`a/b` and `a_b`) stay two files.
std::string unique_name(const std::string& base, std::set<std::string>& used) {
  std::string name = base;
  for (int n = 2; !used.insert(name).second; ++n) name = base + "-" + std::to_string(n);
  return name;
}

// The scene's PNG, JPEG and WebP images copied beside the page (report/SCENE/NAME.EXT, each name
// its own file), in image order with their names; a browser cannot show KTX2. Every copy passes the
// build's output gate: inside the output folder's real path (no link on the way), never an input
// or a job's output. Best effort otherwise: a scene that cannot be read shows none.
std::vector<std::pair<std::string, std::string>> copy_scene_images(const Job& job, const fs::path& folder, const OutputGate& gate,
                                                                   const fs::path& page_folder, std::vector<std::string>& problems) {
  std::vector<std::pair<std::string, std::string>> shown;  // image name, href
  if (job.outputs.scene.empty() || !fs::exists(job.outputs.scene)) return shown;
  auto doc = gltf::read_document(job.outputs.scene);
  if (!doc) return shown;
  std::set<std::string> used;
  const gltf::Json& images = gltf::array_in(doc->json, "images");
  for (std::size_t i = 0; i < images.size(); ++i) {
    const std::string mime = images[i].value("mimeType", "");
    std::string ext = mime == "image/png" ? ".png" : mime == "image/jpeg" ? ".jpg" : mime == "image/webp" ? ".webp" : "";
    if (images[i].contains("uri") && images[i]["uri"].is_string()) {
      const std::string uri = images[i]["uri"].get<std::string>();
      for (const char* e : {".png", ".jpg", ".jpeg", ".webp"}) {
        if (uri.size() > std::string(e).size() && uri.ends_with(e)) ext = e;
      }
    }
    if (ext.empty()) continue;
    auto bytes = gltf::image_bytes(*doc, i);
    if (!bytes) continue;
    const std::string name = gltf::name_in(images[i], "image_" + std::to_string(i));
    const fs::path file = folder / (unique_name(file_safe(name), used) + ext);
    Status s = gate.holds(file) ? gate.check_side_output(file, "the report page's copy of an image")
                                : Status(Error{file.string(), "leaves the output folder (a link on the way); the report page writes only inside it"});
    if (s) s = write_file_atomically(file, *bytes);
    if (!s) {
      problems.push_back(s.error().to_string());
      continue;
    }
    shown.emplace_back(name, href(file, page_folder));
  }
  return shown;
}

std::string scene_section(const JobView& v, const fs::path& folder, const OutputGate& gate, const fs::path& page_folder,
                          std::vector<std::string>& problems) {
  const std::string name = v.job->name.substr(v.job->name.find(':') + 1);
  std::string out = "<section id=\"" + html(v.job->name) + "\"><h3>" + html(name) + "</h3><p>" +
                    html(v.job->outputs.scene.filename().string()) + ", " + number(v.seconds, "%.2f") + " s";
  if (v.details.contains("ao_rays")) out += ", " + number(v.details["ao_rays"], "%.0f") + " AO rays";
  out += "</p>";
  const auto images = copy_scene_images(*v.job, folder, gate, page_folder, problems);
  const json& ao = member(v.details, "ao_textures");
  if (ao.is_array() && !ao.empty()) {
    out += "<h4>AO textures</h4><div class=\"figures\">";
    for (const json& t : ao) {
      if (!t.is_object()) continue;
      const std::string file = text_in(t, "file");
      const std::string image = file.substr(0, file.rfind('.'));
      const std::string caption = text_in(t, "name") + ": mean " + number(member(t, "mean_ao"), "%.3f");
      const auto found = std::find_if(images.begin(), images.end(), [&](const auto& shown) { return shown.first == image; });
      if (found != images.end()) {
        out += figure(found->second, caption);
      } else {
        out += "<figure><figcaption>" + html(caption) + " (in the scene; not shown)</figcaption></figure>";
      }
    }
    out += "</div>";
  }
  const json& textures = member(v.details, "textures");
  if (textures.is_array() && !textures.empty()) {
    out += "<h4>Textures</h4><table><tr><th>texture</th><th>class</th><th>source</th><th>delivered</th><th>needed side</th>"
           "<th>codec</th><th>levels</th><th>bytes</th><th>time (s)</th><th>per level, level 0 first</th><th>note</th></tr>";
    for (const json& t : textures) {
      if (!t.is_object()) continue;
      const auto size = [&](const char* key) {
        const json& s = member(t, key);
        return s.is_array() && s.size() == 2 ? number(s[0], "%.0f") + "×" + number(s[1], "%.0f") : std::string("-");
      };
      out += "<tr><td>" + number(member(t, "texture"), "%.0f") + "</td><td>" + html(text_in(t, "class")) + "</td><td>" +
             size("source_size") + "</td><td>" + size("size") + "</td><td>" + number(member(t, "needed_side"), "%.0f") +
             "</td><td>" + html(text_in(t, "codec")) + "</td><td>" + number(member(t, "levels"), "%.0f") + "</td><td>" +
             number(member(t, "bytes"), "%.0f") + "</td><td>" + number(member(t, "seconds"), "%.2f") + "</td><td>" +
             per_level(t) + "</td><td>" + html(text_in(t, "note")) + "</td></tr>";
    }
    out += "</table>";
  }
  if (!images.empty()) {
    out += "<h4>Images</h4><div class=\"figures\">";
    for (const auto& [image, src] : images) out += figure(src, image);
    out += "</div>";
  }
  for (const std::string& w : v.warnings) out += "<p class=\"warning\">" + html(w) + "</p>";
  if (!v.error.empty()) out += "<p class=\"error\">" + html(v.error) + "</p>";
  return out + "</section>";
}

constexpr const char* kStyle =
    "body{font:14px system-ui,sans-serif;margin:2em;max-width:1200px;color:#222}"
    "table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:2px 6px;text-align:left}"
    "tr.failed td{background:#fdd}tr.built td{background:#efe}"
    ".figures{display:flex;flex-wrap:wrap;gap:12px}figure{margin:0}figure img{width:160px;height:160px;"
    "object-fit:contain;image-rendering:pixelated;background:#888}figcaption{font-size:12px;max-width:160px;overflow-wrap:anywhere}"
    ".warning{color:#a60}.error{color:#b00}";

}  // namespace

Status check_report_page(const Manifest& manifest, const Plan& plan, const fs::path& page) {
  if (!is_really_inside(manifest.output, page)) {
    return Error{page.string(), "the report page goes inside the output folder (" + manifest.output.string() + ")", true};
  }
  const NamedOutput outputs[] = {{page, "report"}};
  return check_side_outputs(manifest, plan, outputs);
}

Status write_report_page(const Manifest& manifest, const Plan& plan, const Report& report, const fs::path& page) {
  if (Status s = check_report_page(manifest, plan, page); !s) return s;
  const StampRoots roots{plan.state_folder, manifest.folder, manifest.output};
  const fs::path folder = page.parent_path();
  const std::vector<JobView> views = job_views(report, roots);
  std::map<std::string, std::size_t> counts;
  for (const JobView& v : views) ++counts[v.outcome];
  std::string body = "<h1>" + html(manifest.file.filename().string()) + "</h1><p>" + html(manifest.file.string()) + " → " +
                     html(manifest.output.string()) + "</p><p>";
  for (const auto& [outcome, n] : counts) body += html(outcome) + " " + std::to_string(n) + " ";
  body += "</p>" + jobs_table(views);
  std::vector<std::string> problems;
  const OutputGate gate = output_gate(manifest, plan);
  std::set<std::string> scene_folders;
  std::string materials = "<h2 id=\"materials\">Materials</h2>", scenes = "<h2 id=\"scenes\">Scenes</h2>";
  for (const JobView& v : views) {
    if (v.job->kind == JobKind::material) {
      materials += material_section(v, folder);
    } else {
      const fs::path images = folder / "report" / unique_name(file_safe(v.job->name), scene_folders);
      scenes += scene_section(v, images, gate, folder, problems);
    }
  }
  for (const std::string& w : plan.warnings) body += "<p class=\"warning\">" + html(w) + "</p>";
  const std::string text = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>matbake: " +
                           html(manifest.file.filename().string()) + "</title><style>" + kStyle + "</style></head><body>" + body +
                           materials + scenes + "</body></html>\n";
  if (!problems.empty()) return Error{page.string(), problems.front()};
  return write_file_atomically(page, text);
}

}  // namespace matbake::pipeline
