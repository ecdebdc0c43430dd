// Tile files (terrain/src/exr_codec.cpp, private): tiles written in the earlier layouts, made here
// with OpenEXR as those versions wrote them, are read exactly; the current layouts round-trip.
#include <gtest/gtest.h>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfTiledOutputFile.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <strata/terrain/tile_store.hpp>

#include "exr_codec.hpp"
#include "strata_test.hpp"

namespace strata::terrain::detail {
namespace {

using gis::Grid;

// A 64^2 tile of whole-number relief with a void, and its mip chain of box means.
std::vector<Grid<float>> reliefLevels() {
  Grid<float> g(64, 64);
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) g.at(x, y) = float(1000 + 3 * x - 2 * y + (x * y) % 7);
  }
  g.at(10, 20) = gis::kNoData;
  std::vector<Grid<float>> levels{g};
  while (levels.back().width > 1) levels.push_back(boxDownsample(levels.back(), 2));
  return levels;
}

// The tile as the earlier versions wrote it: one FLOAT channel per field under ZIP (`low`
// false), or the sample's high bits under PXR24 with its 8 low bits as FIELD~low (`low` true),
// in 64^2 EXR tiles; written to `file` by OpenEXR, returned as bytes.
std::vector<char> earlierTile(const std::vector<Grid<float>>& levels, bool low, const std::filesystem::path& file) {
  Imf::Header header(levels[0].width, levels[0].height);
  header.compression() = low ? Imf::PXR24_COMPRESSION : Imf::ZIP_COMPRESSION;
  header.channels().insert("bedrock", Imf::Channel(Imf::FLOAT));
  if (low) header.channels().insert("bedrock~low", Imf::Channel(Imf::UINT));
  header.setTileDescription(Imf::TileDescription(64, 64, Imf::MIPMAP_LEVELS, Imf::ROUND_DOWN));
  {
    Imf::TiledOutputFile out(file.c_str(), header, 1);
    for (int l = 0; l < out.numLevels(); ++l) {
      Grid<float> high = levels[size_t(l)];
      std::vector<uint32_t> bits(high.size());
      for (size_t i = 0; i < high.size(); ++i) {
        std::memcpy(&bits[i], &high.data[i], 4);
        if (!low) continue;
        const uint32_t h = bits[i] & ~0xffu;
        std::memcpy(&high.data[i], &h, 4);
        bits[i] &= 0xffu;
      }
      Imf::FrameBuffer fb;
      const size_t row = size_t(high.width);
      fb.insert("bedrock", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(high.data.data()), 4, 4 * row));
      if (low) fb.insert("bedrock~low", Imf::Slice(Imf::UINT, reinterpret_cast<char*>(bits.data()), 4, 4 * row));
      out.setFrameBuffer(fb);
      out.writeTiles(0, out.numXTiles(l) - 1, 0, out.numYTiles(l) - 1, l);
    }
  }
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void expectSameBits(const Grid<float>& a, const Grid<float>& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (size_t i = 0; i < a.size(); ++i) {
    const bool bothVoid = std::isnan(a.data[i]) && std::isnan(b.data[i]);
    ASSERT_TRUE(bothVoid || std::memcmp(&a.data[i], &b.data[i], 4) == 0)
        << what << ": sample " << i << " " << a.data[i] << " read as " << b.data[i];
  }
}

TEST(TileFiles, TheEarlierLayoutsAreReadExactly) {
  const auto levels = reliefLevels();  // exact means: the float layouts
  for (bool low : {false, true}) {
    const auto bytes = earlierTile(levels, low, test::tempDir("exr-codec") / "old.exr");
    for (int l : {0, 1, 6}) {
      auto read = decodeTileExrLevel("old.exr", bytes, {"bedrock"}, l);
      ASSERT_TRUE(read) << read.message();
      expectSameBits(levels[size_t(l)], (*read)[0],
                     std::string(low ? "PXR24 + low bits" : "ZIP") + ", level " + std::to_string(l));
    }
  }
}

// The current layouts: a whole-number field (levels rounded, as the store writes them) as
// integers, a float field beside it in the same tile; each level read back exactly.
TEST(TileFiles, IntegerAndFloatFieldsRoundTripInOneTile) {
  auto whole = reliefLevels();
  for (size_t l = 1; l < whole.size(); ++l) {
    for (float& v : whole[l].data) v = std::nearbyint(v);
  }
  auto fractional = reliefLevels();
  for (auto& g : fractional) {
    for (float& v : g.data) v = v * 0.1f + 0.05f;
  }
  std::vector<std::vector<Grid<float>>> levels;
  for (size_t l = 0; l < whole.size(); ++l) levels.push_back({whole[l], fractional[l]});
  const auto bytes = encodeTileExr({"bedrock", "sand"}, levels, "tag");
  const std::string file(bytes.begin(), bytes.end());  // the header names the channels
  EXPECT_NE(file.find("bedrock~int"), std::string::npos);
  EXPECT_EQ(file.find("bedrock~low"), std::string::npos);
  EXPECT_NE(file.find("sand~low"), std::string::npos);
  for (int l = 0; l < int(levels.size()); ++l) {
    auto read = decodeTileExrLevel("new.exr", bytes, {"bedrock", "sand"}, l);
    ASSERT_TRUE(read) << read.message();
    expectSameBits(whole[size_t(l)], (*read)[0], "integer field, level " + std::to_string(l));
    expectSameBits(fractional[size_t(l)], (*read)[1], "float field, level " + std::to_string(l));
  }
}

}  // namespace
}  // namespace strata::terrain::detail
