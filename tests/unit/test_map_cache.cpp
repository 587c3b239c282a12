// The bake's kept maps (bake/map_cache): what store_maps keeps reads back bit for bit, and an index
// that anyone with write access changed (any value of it made each JSON type in turn) is either
// read as the same maps or not used at all; never an exception (a build's job failure) or a map of
// another size.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

#include "lib/src/bake/map_cache.hpp"
#include "support/files.hpp"
#include "support/temp_dir.hpp"

namespace matbake::bake {
namespace {

using nlohmann::json;

constexpr int kSide = 2;

Bake two_targets() {
  Bake out;
  out.boxes = {2.5, 250, 0.75};
  std::vector<TextureBake>& baked = out.textures;
  baked.resize(2);
  for (std::size_t t = 0; t < baked.size(); ++t) {
    baked[t].width = baked[t].height = kSide;
    baked[t].texels = 3 + t, baked[t].missed_texels = t, baked[t].padded = 1;
    baked[t].samples = 12 + t, baked[t].misses = 2 * t, baked[t].from_inside = 5, baked[t].outside_tile = 6;
    baked[t].height_min = -0.25, baked[t].height_max = 0.5 + double(t), baked[t].reach_front = 0.125;
    baked[t].maps.push_back({Map::height, 1, {0.f, 0.125f, float(t), -1.f}});
  }
  return out;
}

// Every place in `j` (objects' members and arrays' items, `j` itself too) as a JSON pointer.
void places(const json& j, const json::json_pointer& at, std::vector<json::json_pointer>& out) {
  out.push_back(at);
  if (j.is_object()) {
    for (const auto& [key, value] : j.items()) places(value, at / key, out);
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i) places(j[i], at / i, out);
  }
}

TEST(MapCache, KeptMapsReadBackExactly) {
  const test::TempDir dir;
  const Bake bake = two_targets();
  const std::vector<TextureBake>& baked = bake.textures;
  ASSERT_TRUE(store_maps(dir.path(), bake, "trace-key", {{Map::height, "height-key"}}));
  const auto kept = load_map(dir.path(), Map::height, "height-key", 2, kSide, kSide);
  ASSERT_TRUE(kept);
  ASSERT_EQ(kept->images.size(), 2u);
  for (std::size_t t = 0; t < 2; ++t) EXPECT_EQ(kept->images[t].values, baked[t].maps[0].values);
  EXPECT_FALSE(load_map(dir.path(), Map::height, "other-key", 2, kSide, kSide));
  EXPECT_FALSE(load_map(dir.path(), Map::height, "height-key", 2, kSide + 1, kSide));
  EXPECT_FALSE(load_map(dir.path(), Map::normal, "height-key", 2, kSide, kSide));
  const auto counts = load_trace(dir.path(), "trace-key", 2);
  ASSERT_TRUE(counts);
  ASSERT_EQ(counts->textures.size(), 2u);
  const TextureBake& second = counts->textures[1];
  EXPECT_EQ(second.texels, 4u);
  EXPECT_EQ(second.missed_texels, 1u);
  EXPECT_EQ(second.height_max, 1.5);
  // The rays and misses of the trace kept: a build that reuses it reports them, not zeros.
  EXPECT_EQ(second.samples, 13u);
  EXPECT_EQ(second.misses, 2u);
  EXPECT_EQ(second.from_inside, 5u);
  EXPECT_EQ(second.outside_tile, 6u);
  EXPECT_EQ(second.reach_front, 0.125);
  EXPECT_EQ(counts->boxes.high_diagonal, 250);
  EXPECT_EQ(counts->boxes.overlap, 0.75);
  EXPECT_FALSE(load_trace(dir.path(), "trace-key", 1));
}

TEST(MapCache, AnIndexChangedAnywhereIsUsedWholeOrNotAtAll) {
  const test::TempDir dir;
  const Bake bake = two_targets();
  const std::vector<TextureBake>& baked = bake.textures;
  ASSERT_TRUE(store_maps(dir.path(), bake, "trace-key", {{Map::height, "height-key"}}));
  const json index = json::parse(test::read_bytes(dir / "maps.json"));
  std::vector<json::json_pointer> at;
  places(index, json::json_pointer(), at);
  const json values[] = {nullptr, true, -1, 1, 1.5, std::numeric_limits<std::uint64_t>::max(), "x", json::array(), json::object()};
  for (const json::json_pointer& place : at) {
    for (const json& value : values) {
      json changed = index;
      changed[place] = value;
      test::write_bytes(dir / "maps.json", changed.dump());
      SCOPED_TRACE(place.to_string() + " = " + value.dump());
      try {
        const auto kept = load_map(dir.path(), Map::height, "height-key", 2, kSide, kSide);
        if (kept) {
          ASSERT_EQ(kept->images.size(), 2u);
          for (std::size_t t = 0; t < 2; ++t) EXPECT_EQ(kept->images[t].values, baked[t].maps[0].values);
        }
        const auto counts = load_trace(dir.path(), "trace-key", 2);
        if (counts) {
          EXPECT_EQ(counts->textures.size(), 2u);
        }
        EXPECT_TRUE(store_maps(dir.path(), bake, "trace-key", {{Map::height, "height-key"}}));
      } catch (const std::exception& e) {
        ADD_FAILURE() << "threw: " << e.what();
      }
    }
  }
}

}  // namespace
}  // namespace matbake::bake

namespace matbake::bake {
namespace {

// A kept map is keyed by the parameters it reads: the part matching by every map, the occluders only
// by those whose rays from the hit they decide (ao, bent_normal, thickness), and only when matching.
TEST(MapCache, MatchKeysEveryMapAndOccludersOnlyTheHitsRaysWhenMatching) {
  const auto key = [](Map map, Match match, Occluders occluders) {
    Request request;
    request.bake.match = match, request.bake.occluders = occluders;
    return map_key("inputs", map, request, "targets");
  };
  for (Map map : {Map::normal, Map::height, Map::ao, Map::bent_normal, Map::thickness, Map::id}) {
    const bool secondary = map == Map::ao || map == Map::bent_normal || map == Map::thickness;
    SCOPED_TRACE(std::string(name_in(kMapNames, map)));
    EXPECT_NE(key(map, Match::always, Occluders::matched), key(map, Match::by_name, Occluders::matched));
    EXPECT_EQ(key(map, Match::always, Occluders::matched), key(map, Match::always, Occluders::all));
    EXPECT_EQ(key(map, Match::by_name, Occluders::matched) != key(map, Match::by_name, Occluders::all), secondary);
  }
}

}  // namespace
}  // namespace matbake::bake
