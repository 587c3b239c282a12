// Parameter descriptions (matbake/params.hpp): values decoded and checked by kind and range, and
// every AO parameter walked: reachable from the command line and the manifest with the same effect,
// round-tripped through the stamp's JSON, and documented in docs/build.md's table.
#include <gtest/gtest.h>

#include "lib/src/delivery/profiles.hpp"

#include <cstdlib>
#include <map>
#include <regex>
#include <sstream>

#include "cli/params_cli.hpp"
#include "matbake/ao_params.hpp"
#include "matbake/bake_ao_params.hpp"
#include "matbake/bake_params.hpp"
#include "matbake/convert_params.hpp"
#include "matbake/delivery_params.hpp"
#include "matbake/encoding_params.hpp"
#include "matbake/export_params.hpp"
#include "matbake/material_params.hpp"
#include "matbake/join.hpp"
#include "matbake/params.hpp"
#include "matbake/preview_params.hpp"
#include "matbake/validate_params.hpp"
#include "matbake/pipeline.hpp"
#include "matbake/cluster.hpp"
#include "matbake/pipeline_params.hpp"
#include "support/files.hpp"
#include "support/param_values.hpp"

namespace matbake::params {
namespace {

namespace fs = std::filesystem;

template <class T>
std::string problem(const Result<T>& r) {
  return r ? "" : r.error().message;
}

TEST(Params, ValuesAreCheckedByKindAndRange) {
  const Spec count{.name = "samples", .kind = Kind::integer, .min = 1, .max = 64};
  EXPECT_EQ(std::get<std::int64_t>(*accept(count, *from_text(count, "64"))), 64);
  EXPECT_EQ(problem(accept(count, *from_text(count, "65"))), "1 to 64");
  EXPECT_EQ(problem(accept(count, *from_text(count, "0"))), "1 to 64");
  EXPECT_EQ(problem(from_text(count, "4.5")), "an integer expected");
  EXPECT_EQ(problem(from_text(count, "")), "an integer expected");
  EXPECT_EQ(problem(accept(count, Value(4.0))), "an integer expected");  // a TOML float is no integer
  EXPECT_EQ(problem(accept(count, Value(std::string("4")))), "an integer expected");

  const Spec distance{.name = "tau", .kind = Kind::number, .min = 0, .max = HUGE_VAL, .above_min = true};
  EXPECT_EQ(std::get<double>(*accept(distance, Value(std::int64_t(2)))), 2.0);  // an integer is a number
  EXPECT_EQ(problem(accept(distance, Value(0.0))), "above 0");
  EXPECT_EQ(problem(accept(distance, Value(std::nan("")))), "above 0");
  EXPECT_EQ(problem(accept(distance, Value(HUGE_VAL))), "above 0");
  EXPECT_EQ(problem(from_text(distance, "1e-3x")), "a number expected");
  EXPECT_DOUBLE_EQ(std::get<double>(*accept(distance, *from_text(distance, "1e-300"))), 1e-300);
  const Spec bias{.name = "bias", .kind = Kind::number, .min = 0, .max = HUGE_VAL};
  EXPECT_EQ(problem(accept(bias, Value(0.0))), "");
  EXPECT_EQ(problem(accept(bias, Value(-1e-9))), "at least 0");

  const Spec pick{.name = "sampler", .kind = Kind::choice, .choices = {"sobol", "random", "halton"}};
  EXPECT_EQ(problem(accept(pick, Value(std::string("Sobol")))), "use sobol, random or halton");
  EXPECT_EQ(problem(accept(pick, Value(true))), "use sobol, random or halton");
  const Spec on{.name = "two_sided", .kind = Kind::flag};
  EXPECT_EQ(problem(accept(on, Value(std::int64_t(1)))), "true or false expected");
  const Spec size{.name = "texture", .kind = Kind::integer_or_text};
  EXPECT_TRUE(std::holds_alternative<std::int64_t>(*from_text(size, "1024")));
  EXPECT_TRUE(std::holds_alternative<std::string>(*from_text(size, "2048x1024")));

  EXPECT_EQ(flag_name(Spec{.name = "relative_distance"}, "ao-"), "--ao-relative-distance");
  EXPECT_EQ(type_text(count), "integer, 1 to 64");
  EXPECT_EQ(type_text(distance), "number, above 0");
  EXPECT_EQ(value_text(nlohmann::json(1e-5)), "1e-05");
  EXPECT_EQ(value_text(nlohmann::json(0.25)), "0.25");
  EXPECT_EQ(value_text(nlohmann::json(64)), "64");
}

// A stamp's value back as the door would give it (null: unset, not given).
std::optional<Value> from_json(const nlohmann::json& j) {
  if (j.is_boolean()) return Value(j.get<bool>());
  if (j.is_number_integer()) return Value(j.get<std::int64_t>());
  if (j.is_number()) return Value(j.get<double>());
  if (j.is_string()) return Value(j.get<std::string>());
  return std::nullopt;
}

// --- Each command's request tree, walked through both doors ------------------------------------------

// A parameter of a tree set to a value.
template <class Root>
struct Setting {
  std::size_t branch;
  const Spec* spec;
  std::string value;
};

// The spec a rule names: in its own branch first, then in each in order (as check_rules looks).
template <class Root>
Setting<Root> find_setting(const Tree<Root>& tree, std::size_t own, const std::string& name, const std::string& value) {
  for (std::size_t k = 0; k <= tree.size(); ++k) {
    const std::size_t b = k == 0 ? own : k - 1;
    for (const Spec* spec : tree[b].specs) {
      if (spec->name == name) return {b, spec, value.empty() ? spec->example : value};
    }
  }
  ADD_FAILURE() << "no parameter " << name;
  return {own, nullptr, value};
}

// What `spec` needs that the defaults do not give (each at the value it needs, or its example), and
// what those need in turn (vertex_existing_colors: vertex_ao_into = COLOR_0, which needs ao among
// vertex_maps), onto `out`, each once.
template <class Root>
void add_needs(const Tree<Root>& tree, std::size_t b, const Spec* spec, std::vector<Setting<Root>>& out) {
  for (const Condition& c : spec->needs) {
    // A list rule: the list holding its last name alone (green's bent_normal: the normal map with
    // green directx is refused for the glTF it goes into).
    const std::string value = c.among ? split(c.value, ',').back() : c.value;
    const Setting<Root> needed = find_setting(tree, b, c.name, value);
    const bool listed = std::ranges::any_of(out, [&](const Setting<Root>& s) { return s.spec == needed.spec; });
    if (!listed && (c.value.empty() || value_text(tree[needed.branch].values(Root{}).at(c.name)) != value)) {
      out.push_back(needed);
      add_needs(tree, needed.branch, needed.spec, out);
    }
  }
}

// The parameter at its example and all it needs (add_needs).
template <class Root>
std::vector<Setting<Root>> with_needs(const Tree<Root>& tree, std::size_t b, const Spec* spec) {
  std::vector<Setting<Root>> out{{b, spec, spec->example}};
  add_needs(tree, b, spec, out);
  return out;
}

template <class Root>
std::string flag_of(const Tree<Root>& tree, const Setting<Root>& s) { return flag_name(*s.spec, tree[s.branch].flag_prefix); }

template <class Root>
std::string key_of(const Tree<Root>& tree, const Setting<Root>& s) {
  return "scenes.s." + (tree[s.branch].table.empty() ? "" : tree[s.branch].table + ".") + s.spec->name;
}

// The command line's request from the settings, through the tree as a command adds it.
template <class Root>
Result<Root> from_flags(const Tree<Root>& tree, const std::vector<Setting<Root>>& settings) {
  CLI::App app;
  Root root;
  std::vector<std::set<std::string>> given;
  cli::add_tree(app, tree, root, given, std::vector<std::string>(tree.size(), "Options"));
  std::vector<std::string> args;
  for (const Setting<Root>& s : settings) {
    const std::string flag = flag_of(tree, s);
    if (s.spec->kind != Kind::flag) {
      args.insert(args.end(), {flag, s.value});
    } else {
      args.push_back(s.value == "true" ? flag : "--no-" + flag.substr(2));
    }
  }
  std::reverse(args.begin(), args.end());  // CLI11 takes them last first
  try {
    app.parse(args);
  } catch (const CLI::ParseError& e) {
    return Error{"", e.what(), true};
  }
  if (Status st = cli::finish_tree(tree, root, given); !st) return st.error();
  return root;
}

// A manifest scene's request from the same settings: its own keys, and its tables' (ao = { ... }).
Result<exporter::Options> from_scene_keys(const Tree<exporter::Options>& tree, const std::vector<Setting<exporter::Options>>& settings) {
  std::string own, ao;
  for (const Setting<exporter::Options>& s : settings) {
    const std::string key = s.spec->name + " = " + toml_value_text(*s.spec, s.value);
    if (tree[s.branch].table.empty()) {
      own += key + "\n";
    } else {
      ao += (ao.empty() ? "" : ", ") + key;
    }
  }
  auto m = pipeline::parse_manifest("[scenes.s]\ninput = \"s.gltf\"\n" + own + (ao.empty() ? "" : "ao = { " + ao + " }\n"),
                                    "/p/assets.toml");
  if (!m) return m.error();
  return m->scenes.at(0).options;
}

// Export's tree is a manifest scene's: each parameter at its example (with what it needs) gives the
// same request through the flags and the scene's keys, one that differs from the defaults.
TEST(RequestTree, EveryParameterOfExportsTreeReachesTheSceneFromBothDoors) {
  const Tree<exporter::Options>& tree = exporter::request_tree();
  const nlohmann::json defaults = tree_json(tree, exporter::Options{});
  std::size_t walked = 0;
  for (std::size_t b = 0; b < tree.size(); ++b) {
    for (const Spec* spec : tree[b].specs) {
      SCOPED_TRACE(spec->name);
      const auto settings = with_needs(tree, b, spec);
      auto cli = from_flags(tree, settings);
      auto manifest = from_scene_keys(tree, settings);
      ASSERT_TRUE(cli) << cli.error().to_string();
      ASSERT_TRUE(manifest) << manifest.error().to_string();
      const nlohmann::json shown = tree_json(tree, *cli);
      EXPECT_EQ(shown, tree_json(tree, *manifest));
      EXPECT_NE(tree[b].values(*cli).at(spec->name), tree[b].values(exporter::Options{}).at(spec->name))
          << "the example must differ from the default";
      EXPECT_NE(shown, defaults);
      // The values shown (as stamps hold them), given again where not the defaults, make the same request.
      exporter::Options again;
      for (const Branch<exporter::Options>& other : tree) {
        const nlohmann::json values = other.values(*cli), unset = other.values(exporter::Options{});
        for (const Spec* s : other.specs) {
          if (auto v = from_json(values.at(s->name)); v && values.at(s->name) != unset.at(s->name)) {
            EXPECT_EQ(other.apply(again, *s, *v), std::nullopt) << s->name;
          }
        }
      }
      EXPECT_EQ(tree_json(tree, again), shown);
      ++walked;
    }
  }
  EXPECT_EQ(walked, 62u);  // a new parameter is walked here too
}

// Each rule of a tree broken on purpose: refused at both doors, with one message in each door's spelling.
template <class Root, class ManifestDoor>
void walk_rules(const Tree<Root>& tree, ManifestDoor manifest_door, std::size_t expected_rules) {
  std::size_t rules = 0;
  for (std::size_t b = 0; b < tree.size(); ++b) {
    for (const Spec* spec : tree[b].specs) {
      const Setting<Root> self{b, spec, spec->example};
      for (std::size_t i = 0; i < spec->needs.size(); ++i) {
        const Condition& c = spec->needs[i];
        SCOPED_TRACE(spec->name + " needs " + c.name);
        std::vector<Setting<Root>> settings{self};
        for (std::size_t j = 0; j < i; ++j) settings.push_back(find_setting(tree, b, spec->needs[j].name, spec->needs[j].value));
        const Setting<Root> needed = find_setting(tree, b, c.name, "");
        std::string flag_words = " as well", key_words = " as well";
        if (!c.value.empty()) {  // the needed parameter at another of its values
          const bool flag = needed.spec->kind == Kind::flag;
          const std::vector<std::string> values = flag ? std::vector<std::string>{"true", "false"} : needed.spec->choices;
          const auto other = std::find_if(values.begin(), values.end(), [&](const std::string& v) { return v != c.value; });
          ASSERT_NE(other, values.end());
          // A flag at its default is a flag not given (a default-false flag has no --no- form).
          if (!flag || *other != value_text(tree[needed.branch].values(Root{}).at(needed.spec->name))) {
            settings.push_back({needed.branch, needed.spec, *other});
          }
          flag_words = flag && c.value == "true" ? "" : " " + c.value;  // "--mesh-quantization", not "... true"
          key_words = " = " + toml_value_text(*needed.spec, c.value);
        }
        auto cli = from_flags(tree, settings);
        ASSERT_FALSE(cli);
        EXPECT_EQ(cli.error().message, flag_of(tree, self) + " applies only with " + flag_of(tree, needed) + flag_words);
        manifest_door(settings, key_of(tree, self) + " applies only with " + key_of(tree, needed) + key_words);
        ++rules;
      }
      for (const std::string& other : spec->excludes) {
        SCOPED_TRACE(spec->name + " excludes " + other);
        std::vector<Setting<Root>> settings = with_needs(tree, b, spec);
        const Setting<Root> excluded = find_setting(tree, b, other, "");
        settings.push_back(excluded);
        auto cli = from_flags(tree, settings);
        ASSERT_FALSE(cli);
        EXPECT_EQ(cli.error().message, flag_of(tree, self) + " and " + flag_of(tree, excluded) + " cannot be given together");
        manifest_door(settings, key_of(tree, self) + " and " + key_of(tree, excluded) + " cannot be given together");
        ++rules;
      }
    }
  }
  EXPECT_EQ(rules, expected_rules);  // a new rule is walked here too
}

TEST(RequestTree, EveryRuleIsEnforcedAtBothDoorsInTheirOwnSpelling) {
  const Tree<exporter::Options>& tree = exporter::request_tree();
  walk_rules(tree, [&](const std::vector<Setting<exporter::Options>>& settings, const std::string& expected) {
    auto manifest = from_scene_keys(tree, settings);
    ASSERT_FALSE(manifest);
    EXPECT_EQ(manifest.error().message, expected);
    EXPECT_EQ(manifest.error().path.rfind("/p/assets.toml:", 0), 0u) << manifest.error().path;
  }, 48);
}

// A manifest entry's settings as TOML: the plain branches' as keys, each table's as name = { ... }.
template <class Root>
std::string toml_of(const Tree<Root>& tree, const std::vector<Setting<Root>>& settings) {
  std::string own;
  std::map<std::string, std::string> tables;
  for (const Setting<Root>& s : settings) {
    const std::string key = s.spec->name + " = " + toml_value_text(*s.spec, s.value);
    const std::string& table = tree[s.branch].table;
    if (table.empty()) {
      own += key + "\n";
    } else {
      tables[table] += (tables[table].empty() ? "" : ", ") + key;
    }
  }
  for (const auto& [table, keys] : tables) own += table + " = { " + keys + " }\n";
  return own;
}

// Each parameter of an entry's tree given at the manifest's top level reaches the entry as if the
// entry gave it (one rule for every group: materials' and scenes'), and the entry's own key wins.
// Not a scene's `bake` table: a scene bakes only when its own table has one, naming its high-poly
// (the top level's gives the baking scenes their defaults: BuildManifest.EveryKeyReachesItsField).
template <class Root, class Read>
void walk_top_level(const Tree<Root>& tree, const std::string& entry, Read read, std::size_t expected) {
  std::size_t walked = 0;
  for (std::size_t b = 0; b < tree.size(); ++b) {
    if (tree[b].table.rfind("bake", 0) == 0) continue;
    for (const Spec* spec : tree[b].specs) {
      SCOPED_TRACE(spec->name);
      const std::string keys = toml_of(tree, with_needs(tree, b, spec));
      auto top = pipeline::parse_manifest(keys + entry, "/p/assets.toml");
      auto own = pipeline::parse_manifest(entry + keys, "/p/assets.toml");
      ASSERT_TRUE(top) << top.error().to_string();
      ASSERT_TRUE(own) << own.error().to_string();
      EXPECT_EQ(tree_json(tree, read(*top)), tree_json(tree, read(*own)));
      EXPECT_NE(tree[b].values(read(*top)).at(spec->name), tree[b].values(Root{}).at(spec->name));
      // The entry's default-valued key over the top level's example: the entry's value stands.
      const std::string reset = spec->name + " = " +
                                toml_value_text(*spec, value_text(tree[b].values(Root{}).at(spec->name)));
      if (tree[b].table.empty() && !tree[b].values(Root{}).at(spec->name).is_null()) {
        auto over = pipeline::parse_manifest(keys + entry + reset + "\n", "/p/assets.toml");
        ASSERT_TRUE(over) << over.error().to_string();
        EXPECT_EQ(tree[b].values(read(*over)).at(spec->name), tree[b].values(Root{}).at(spec->name));
      }
      ++walked;
    }
  }
  EXPECT_EQ(walked, expected);
}

TEST(RequestTree, TheTopLevelGivesEveryMaterialAndSceneParameterItsDefault) {
  walk_top_level(pipeline::scene_tree(), "[scenes.s]\ninput = \"s.gltf\"\n",
                 [](const pipeline::Manifest& m) { return m.scenes.at(0); }, 63);
  walk_top_level(pipeline::material_tree(), "[materials.m]\nsources = { kd = 0.5 }\n",
                 [](const pipeline::Manifest& m) { return m.materials.at(0); }, 15);
}

// A delivery profile sets its values first, whatever the order it is given in at either door; the
// settings beside it (and an entry's, over the top level's profile) override them.
TEST(RequestTree, ADeliveryProfileIsSetBeforeTheSettingsBesideIt) {
  const Tree<exporter::Options> tree = exporter::request_tree();
  const auto setting = [&](const std::string& name, const std::string& value) { return find_setting(tree, 0, name, value); };
  const auto web_with_quality = [](const exporter::Options& o) {
    EXPECT_EQ(o.delivery.profile, "web");
    EXPECT_EQ(o.delivery.texture_format, delivery::TextureFormat::ktx2);
    EXPECT_TRUE(o.delivery.geometry.quantize);
    EXPECT_EQ(o.delivery.geometry.compression, delivery::MeshCompression::meshopt);
    EXPECT_EQ(o.delivery.colour.quality, 200);  // the profile's is 192
  };
  for (bool profile_first : {true, false}) {
    std::vector<Setting<exporter::Options>> settings = {setting("delivery_profile", "web"), setting("colour_quality", "200")};
    if (!profile_first) std::swap(settings[0], settings[1]);
    auto cli = from_flags(tree, settings);
    ASSERT_TRUE(cli) << cli.error().to_string();
    web_with_quality(*cli);
    const std::string keys = profile_first ? "delivery_profile = \"web\"\ncolour_quality = 200\n" : "colour_quality = 200\ndelivery_profile = \"web\"\n";
    auto m = pipeline::parse_manifest("[scenes.s]\ninput = \"s.gltf\"\n" + keys, "/p/assets.toml");
    ASSERT_TRUE(m) << m.error().to_string();
    web_with_quality(m->scenes.at(0).options);
  }
  auto inherited = pipeline::parse_manifest("delivery_profile = \"web\"\n[scenes.s]\ninput = \"s.gltf\"\ncolour_quality = 200\n", "/p/assets.toml");
  ASSERT_TRUE(inherited) << inherited.error().to_string();
  web_with_quality(inherited->scenes.at(0).options);
  // A setting the profile's values rule out is refused as any other.
  auto refused = pipeline::parse_manifest("[scenes.s]\ninput = \"s.gltf\"\ndelivery_profile = \"desktop\"\ncolour_quality = 200\n", "/p/assets.toml");
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().message, "scenes.s.colour_quality applies only with scenes.s.colour_codec = \"etc1s\"");
}

// Every profile applies as its parameters read it, keeps the rules, and is what its file says.
TEST(RequestTree, EveryDeliveryProfileAppliesCleanly) {
  ASSERT_EQ(delivery::profile_names(), (std::vector<std::string>{"archive", "desktop", "mobile", "web"}));
  for (const std::string& name : delivery::profile_names()) {
    auto m = pipeline::parse_manifest("[scenes.s]\ninput = \"s.gltf\"\ndelivery_profile = \"" + name + "\"\n", "/p/assets.toml");
    ASSERT_TRUE(m) << name << ": " << m.error().to_string();
    EXPECT_EQ(m->scenes.at(0).options.delivery.profile, name);
    EXPECT_NE(to_json(delivery::options_params(), m->scenes.at(0).options.delivery), to_json(delivery::options_params(), delivery::Options{})) << name;
  }
}

// A rule is checked on each entry as inherited: the top level's colour_quality applies to a KTX2
// scene, and is refused, at its own line, for a scene that is not KTX2.
TEST(RequestTree, AnInheritedParameterIsCheckedInEachEntry) {
  const std::string top = "colour_quality = 200\n[scenes.web]\ninput = \"s.gltf\"\ntexture_format = \"ktx2\"\n";
  auto ok = pipeline::parse_manifest(top, "/p/assets.toml");
  ASSERT_TRUE(ok) << ok.error().to_string();
  EXPECT_EQ(ok->scenes.at(0).options.delivery.colour.quality, 200);
  auto refused = pipeline::parse_manifest(top + "[scenes.plain]\ninput = \"s.gltf\"\n", "/p/assets.toml");
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().path, "/p/assets.toml:1:18");
  EXPECT_EQ(refused.error().message,
            "scenes.plain.colour_quality applies only with scenes.plain.texture_format = \"ktx2\"");
}

// bake-ao's tree: the same groups as export's (so a manifest scene reaches each), its flags unprefixed,
// each parameter reaching the request and each rule enforced in its spelling.
TEST(RequestTree, BakeAosTreeIsExportsGroupsWithItsOwnFlags) {
  const Tree<bake_ao::Options>& tree = bake_ao::request_tree();
  const Tree<exporter::Options>& scene = exporter::request_tree();
  for (const Branch<bake_ao::Options>& b : tree) {
    EXPECT_TRUE(std::any_of(scene.begin(), scene.end(), [&](const Branch<exporter::Options>& s) { return s.specs == b.specs; }));
    EXPECT_EQ(b.flag_prefix, "");
  }
  for (std::size_t b = 0; b < tree.size(); ++b) {
    for (const Spec* spec : tree[b].specs) {
      SCOPED_TRACE(spec->name);
      auto cli = from_flags(tree, with_needs(tree, b, spec));
      ASSERT_TRUE(cli) << cli.error().to_string();
      EXPECT_NE(tree[b].values(*cli).at(spec->name), tree[b].values(bake_ao::Options{}).at(spec->name));
    }
  }
  walk_rules(tree, [](const auto&, const std::string&) {}, 48);
}

// bake's tree: each parameter at its example reaches the request through its flag.
TEST(RequestTree, BakesTreeTakesEveryParameterAtItsExample) {
  const Tree<bake::FileOptions>& tree = bake::request_tree();
  for (std::size_t b = 0; b < tree.size(); ++b) {
    for (const Spec* spec : tree[b].specs) {
      SCOPED_TRACE(spec->name);
      std::vector<Setting<bake::FileOptions>> settings = with_needs(tree, b, spec);
      auto cli = from_flags(tree, settings);
      ASSERT_TRUE(cli) << cli.error().to_string();
      EXPECT_NE(tree[b].values(*cli).at(spec->name), tree[b].values(bake::FileOptions{}).at(spec->name));
    }
  }
}

// The parameters that act only on some maps say so (a rule on a list's values), and both doors
// refuse them with a list that lacks those maps, in one line each in their own spelling; with one
// of the maps among the list, the rule holds.
TEST(RequestTree, BakesListRulesAreEnforcedAtBothDoors) {
  const Tree<bake::FileOptions>& tree = bake::request_tree();
  std::size_t rules = 0;
  for (std::size_t b = 0; b < tree.size(); ++b) {
    for (const Spec* spec : tree[b].specs) {
      for (const Condition& c : spec->needs) {
        if (!c.among) continue;
        SCOPED_TRACE(spec->name + " needs " + c.value + " among " + c.name);
        const Setting<bake::FileOptions> self{b, spec, spec->example}, without = find_setting(tree, b, c.name, "height");
        const std::string alternatives = join(split(c.value, ','), " or ");
        auto cli = from_flags(tree, {self, without});
        ASSERT_FALSE(cli);
        EXPECT_EQ(cli.error().message, flag_of(tree, self) + " applies only with " + alternatives + " among " + flag_of(tree, without));
        const std::string table = "bake = { from = \"h.glb\", " + spec->name + " = " + toml_value_text(*spec, spec->example) + ", " +
                                  c.name + " = \"height\" }";
        auto manifest = pipeline::parse_manifest("[scenes.s]\ninput = \"a.gltf\"\n" + table + "\n", "/p/assets.toml");
        ASSERT_FALSE(manifest);
        // Placed at the value, as every manifest error is.
        const std::size_t column = table.find(spec->name + " = ") + spec->name.size() + 4;
        EXPECT_EQ(manifest.error().to_string(), "/p/assets.toml:3:" + std::to_string(column) + ": scenes.s.bake." +
                                                    spec->name + " applies only with " + alternatives + " among scenes.s.bake." + c.name);
        EXPECT_TRUE(from_flags(tree, with_needs(tree, b, spec)));
        ++rules;
      }
    }
  }
  EXPECT_EQ(rules, 4u);  // green, id_by, high_normal_maps, vertex_ao_into; a new one is walked here too
  // A project-wide default at the manifest's top level applies where it can: the scene baking AO
  // alone is not refused for it; given by that scene itself, it is.
  const std::string scenes = "[scenes.s]\ninput = \"a.gltf\"\nbake = { from = \"h.glb\", maps = [\"normal\"] }\n"
                             "[scenes.t]\ninput = \"b.gltf\"\nbake = { from = \"h.glb\", maps = [\"ao\"] }\n";
  auto inherited = pipeline::parse_manifest("[bake]\nhigh_normal_maps = true\nid_by = \"primitive\"\n" + scenes, "/p/assets.toml");
  EXPECT_TRUE(inherited) << inherited.error().to_string();
  auto own = pipeline::parse_manifest(scenes + "[scenes.u]\ninput = \"c.gltf\"\nbake = { from = \"h.glb\", maps = [\"ao\"], "
                                               "high_normal_maps = true }\n", "/p/assets.toml");
  ASSERT_FALSE(own);
  EXPECT_EQ(own.error().to_string(), "/p/assets.toml:9:60: scenes.u.bake.high_normal_maps applies only with normal among scenes.u.bake.maps");
}

// A request made by the command line from one parameter at its example (a flag on by default
// given as --no-NAME).
template <class T>
T from_example_flag(const Group<T>& group, const Param<T>& p) {
  CLI::App app;
  T target;
  cli::add_params(app, group, target, "", "Options");
  const bool on = p.spec.kind == Kind::flag && to_json(group, T{}).at(p.spec.name) == true;
  std::vector<std::string> args = {on ? "--no-" + flag_name(p.spec, "").substr(2) : flag_name(p.spec, "")};
  if (p.spec.kind != Kind::flag) args.push_back(p.spec.example);
  std::reverse(args.begin(), args.end());  // CLI11 takes them last first
  app.parse(args);
  return target;
}

TEST(ValidateParams, EveryParameterReachesTheMaterialsValidationFromBothDoors) {
  const Group<validate::Options>& group = validate::options_params();
  const nlohmann::json defaults = to_json(group, validate::Options{});
  for (const Param<validate::Options>& p : group.params) {
    SCOPED_TRACE(p.spec.name);
    const validate::Options from_flags = from_example_flag(group, p);
    auto m = pipeline::parse_manifest("[materials.a]\nsources = { kd = 0.5 }\nvalidate = { " + p.spec.name + " = " +
                                          test::toml_literal(p.spec) + " }\n",
                                      "/p/assets.toml");
    ASSERT_TRUE(m) << m.error().to_string();
    EXPECT_EQ(to_json(group, from_flags), to_json(group, m->materials[0].validation.options));
    EXPECT_NE(to_json(group, from_flags).at(p.spec.name), defaults.at(p.spec.name));
  }
}

// A material's options: each at its example through the flags, a material's key and the manifest's
// top level (every material's default), the three stamps equal and not the default's.
TEST(MaterialParams, EveryParameterReachesTheMaterialFromBothDoorsAndTheTopLevel) {
  const Group<pack::MaterialOptions>& group = pack::material_params();
  const nlohmann::json defaults = to_json(group, pack::MaterialOptions{});
  for (const Param<pack::MaterialOptions>& p : group.params) {
    SCOPED_TRACE(p.spec.name);
    const pack::MaterialOptions from_flags = from_example_flag(group, p);
    const std::string key = p.spec.name + " = " + test::toml_literal(p.spec) + "\n";
    auto in_material = pipeline::parse_manifest("[materials.a]\nsources = { kd = 0.5 }\n" + key, "/p/assets.toml");
    auto at_top = pipeline::parse_manifest(key + "[materials.a]\nsources = { kd = 0.5 }\n", "/p/assets.toml");
    ASSERT_TRUE(in_material) << in_material.error().to_string();
    ASSERT_TRUE(at_top) << at_top.error().to_string();
    EXPECT_EQ(to_json(group, from_flags), to_json(group, in_material->materials[0].options));
    EXPECT_EQ(to_json(group, from_flags), to_json(group, at_top->materials[0].options));
    EXPECT_NE(to_json(group, from_flags).at(p.spec.name), defaults.at(p.spec.name));
  }
}

// `convert` has one door: each parameter's example through its flag is what --json echoes.
TEST(ConvertParams, EveryParameterIsAFlagWhoseExampleChangesTheEcho) {
  const Group<convert::Options>& group = convert::options_params();
  const nlohmann::json defaults = to_json(group, convert::Options{});
  for (const Param<convert::Options>& p : group.params) {
    SCOPED_TRACE(p.spec.name);
    const convert::Options options = from_example_flag(group, p);
    nlohmann::json expected = defaults;
    expected[p.spec.name] = p.spec.example;
    EXPECT_EQ(to_json(group, options), expected);
  }
}

TEST(PreviewParams, EveryParameterIsAFlagWhoseExampleChangesTheOptions) {
  const Group<preview::Options> group = preview::options_params();
  const nlohmann::json defaults = to_json(group, preview::Options{});
  for (const Param<preview::Options>& p : group.params) {
    SCOPED_TRACE(p.spec.name);
    const preview::Options options = from_example_flag(group, p);
    EXPECT_NE(to_json(group, options).at(p.spec.name), defaults.at(p.spec.name));
  }
  preview::Options sweep;
  EXPECT_EQ(apply(*group.find("gloss_sweep"), sweep, Value(std::string("0,0.5,1"))), std::nullopt);
  EXPECT_EQ(sweep.glosses, (std::vector<double>{0, 0.5, 1}));
  for (const char* bad : {"0.5,", "1.5", "a", ""}) {
    EXPECT_EQ(apply(*group.find("gloss_sweep"), sweep, Value(std::string(bad))), "gloss values 0 to 1, comma-separated") << bad;
  }
  EXPECT_EQ(apply(*group.find("model"), sweep, Value(std::string("ggxx"))).value_or("").rfind("use lambert", 0), 0u);
}

// A build's own settings have one door: each at its example, through the manifest, changes the
// entry (and so its stamp), and no command takes it as a flag.
TEST(PipelineParams, EveryBuildSettingReachesItsEntryFromTheManifest) {
  for (const Param<pipeline::ValidationRules>& p : pipeline::validation_params().params) {
    SCOPED_TRACE(p.spec.name);
    auto m = pipeline::parse_manifest("[validate]\n" + p.spec.name + " = " + test::toml_literal(p.spec) +
                                          "\n[materials.a]\nsources = { kd = 0.5 }\n",
                                      "/p/assets.toml");
    ASSERT_TRUE(m) << m.error().to_string();
    EXPECT_NE(to_json(pipeline::validation_params(), m->materials[0].validation),
              to_json(pipeline::validation_params(), pipeline::ValidationRules{}));
  }
  for (const Param<pipeline::SceneSpec>& p : pipeline::scene_params().params) {
    SCOPED_TRACE(p.spec.name);
    auto m = pipeline::parse_manifest("[scenes.s]\ninput = \"s.gltf\"\n" + p.spec.name + " = " +
                                          test::toml_literal(p.spec) + "\n",
                                      "/p/assets.toml");
    ASSERT_TRUE(m) << m.error().to_string();
    EXPECT_NE(to_json(pipeline::scene_params(), m->scenes[0]), to_json(pipeline::scene_params(), pipeline::SceneSpec{}));
  }
  CLI::App app;
  pipeline::ValidationRules rules;
  cli::add_params(app, pipeline::validation_params(), rules, "", "Options");
  EXPECT_THROW(app.parse(std::vector<std::string>{"--enabled"}), CLI::ParseError);
}

TEST(MaterialParams, AnOlderFlagWorksAsTheNewOne) {
  CLI::App app;
  pack::MaterialOptions options;
  cli::add_params(app, pack::material_params(), options, "", "Options");
  app.parse(std::vector<std::string>{"linear", "--input-transfer"});
  EXPECT_EQ(options.decode, color::Transfer::linear);
  EXPECT_THROW(app.parse(std::vector<std::string>{"lin", "--decode"}), CLI::ValidationError);
}

TEST(AoParams, OlderManifestKeysAreReadWithANote) {
  auto m = pipeline::parse_manifest("[scenes.s]\ninput = \"s.gltf\"\nao = { distance = 0.1 }\n"
                                    "[scenes.t]\ninput = \"s.gltf\"\nao = { absolute_distance = 2 }\n",
                                    "/p/assets.toml");
  ASSERT_TRUE(m) << m.error().to_string();
  EXPECT_DOUBLE_EQ(m->scenes[0].options.ao->options.relative_distance, 0.1);
  EXPECT_DOUBLE_EQ(m->scenes[1].options.ao->options.absolute_distance, 2);
  EXPECT_EQ(m->notes, (std::vector<std::string>{
                          "/p/assets.toml:3:8: scenes.s.ao.distance is now called relative_distance (the old name still works)",
                          "/p/assets.toml:6:8: scenes.t.ao.absolute_distance is now called max_distance (the old name still works)"}));
}

// Each docs table made from a description stands between markers; MATBAKE_WRITE_DOCS=1 writes it.
TEST(DocsTables, MatchTheParameterDescriptions) {
  struct Table {
    std::string file, marker, text;
  };
  const Table tables[] = {
      {"docs/build.md", "params:ao", markdown_table(ao::request_params(), "")},
      {"docs/build.md", "params:encoding", markdown_table(image::encoding_params(), "")},
      {"docs/export.md", "params:export", markdown_table(exporter::options_params(), "")},
      {"docs/delivery.md", "params:delivery", markdown_table(delivery::options_params(), "")},
      {"docs/validate.md", "params:validate", markdown_table(validate::options_params(), "")},
      {"docs/build.md", "params:material", markdown_table(pack::material_params(), "")},
      {"docs/convert.md", "params:convert", markdown_table(convert::options_params(), "")},
      {"docs/preview.md", "params:preview", markdown_table(preview::options_params(), "")},
      {"docs/build.md", "params:validation", markdown_table(pipeline::validation_params(), "")},
      {"docs/build.md", "params:scene", markdown_table(pipeline::scene_params(), "")},
      {"docs/build.md", "params:bake-source", markdown_table(pipeline::bake_source_params(), "")},
      {"docs/cluster.md", "params:cluster", markdown_table(pipeline::cluster_params(), "")},
      {"docs/bake.md", "params:bake", markdown_table(bake::request_params(), "")},
      {"docs/bake.md", "params:bake-ao", markdown_table(ao::estimator_params(), "ao-")},
  };
  for (const Table& t : tables) {
    const fs::path path = fs::path(MATBAKE_SOURCE_DIR) / t.file;
    std::string doc = test::read_bytes(path);
    const std::size_t begin = doc.find("<!-- " + t.marker + " begin");
    const std::size_t end = doc.find("<!-- " + t.marker + " end -->");
    ASSERT_NE(begin, std::string::npos) << t.file;
    ASSERT_NE(end, std::string::npos) << t.file;
    const std::size_t body = doc.find('\n', begin) + 1;
    if (std::getenv("MATBAKE_WRITE_DOCS")) {
      doc.replace(body, end - body, t.text);
      test::write_bytes(path, doc);
      continue;
    }
    EXPECT_EQ(doc.substr(body, end - body), t.text) << t.file << " " << t.marker
                                                    << ": run MATBAKE_WRITE_DOCS=1 ctest -R DocsTables to write it";
  }
}

// The library names a setting by its parameter (mention()); only a door spells it. A string literal
// in lib/src with "--name" in it is a flag written where a manifest user would read it too. Allowed:
// the commands matbake writes for Ninja and Slurm (they run the command line), sbatch's own flags,
// and the docs table's flag column.
TEST(Sources, NoFlagIsSpeltInTheLibrarysMessages) {
  const std::regex literal_with_flag(R"re("[^"]*--[a-z][^"]*")re");
  std::size_t files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(fs::path(MATBAKE_SOURCE_DIR) / "lib/src")) {
    if (entry.path().extension() != ".cpp" && entry.path().extension() != ".hpp") continue;
    const std::string name = entry.path().filename().string();
    if (name == "slurm.cpp") continue;  // writes sbatch and matbake command lines
    ++files;
    std::istringstream lines(test::read_bytes(entry.path()));
    int number = 0;
    for (std::string line; std::getline(lines, line);) {
      ++number;
      if (!std::regex_search(line, literal_with_flag) || line.find("sbatch") != std::string::npos) continue;
      if (line.find("command = $matbake") != std::string::npos) continue;  // the Ninja rules' command lines
      if (name == "params.cpp" && line.find("shown_flag") != std::string::npos) continue;  // the docs' flag column
      ADD_FAILURE() << entry.path().string() << ":" << number << ": " << line;
    }
  }
  EXPECT_GT(files, 50u);
}


// A name read from a file is printed on one line and cannot steer the terminal: ASCII controls as
// \n, \xNN; UTF-8's C1 controls (NEL breaks a line) and bidirectional overrides (U+202E reverses
// what follows) as \uXXXX; other UTF-8 as it is.
TEST(Messages, EscapeControlWritesTerminalControlsAsEscapes) {
  EXPECT_EQ(escape_control("a\nb\x1b[31m"), "a\\nb\\x1b[31m");
  EXPECT_EQ(escape_control("line\xc2\x85" "break"), "line\\u0085break");
  EXPECT_EQ(escape_control("\xe2\x80\xaetxt.exe"), "\\u202etxt.exe");
  EXPECT_EQ(escape_control("\xe2\x81\xa6x\xe2\x81\xa9"), "\\u2066x\\u2069");
  EXPECT_EQ(escape_control("caf\xc3\xa9 \xe2\x80\x94 \xc2\xa0"), "caf\xc3\xa9 \xe2\x80\x94 \xc2\xa0");  // é, em dash, no-break space
  EXPECT_EQ(escape_control("cut\xc2"), "cut\xc2");  // a truncated sequence: as it is
}
}  // namespace
}  // namespace matbake::params
