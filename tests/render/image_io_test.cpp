// render/image_io.hpp: float fields as ZIP-compressed EXRs (OpenEXR) read back exactly with their
// channel names and attributes; colour images only as .png.
#include <gtest/gtest.h>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <cmath>
#include <filesystem>

#include <strata/render/image_io.hpp>

#include "strata_test.hpp"

namespace strata::render {
namespace {

namespace fs = std::filesystem;

TEST(ImageIo, FloatExrKeepsEveryValueItsNamesAndAttributes) {
  const auto dir = test::tempDir("image-io");
  const int w = 19, h = 11;
  std::vector<float> depth(size_t(w) * h);
  for (size_t i = 0; i < depth.size(); ++i) depth[i] = float(std::sin(double(i)) * 1234.5);
  depth[5] = std::nanf("");
  const std::string one = (dir / "depth.exr").string();
  ASSERT_TRUE(writeImageFloat(one, w, h, 1, depth));
  ExrExtras extras;
  extras.strings = {{"strata:script", "bumps.glsl"}};
  extras.ints = {{"strata:seed", 42}};
  std::vector<float> rg(size_t(w) * h * 2);
  for (size_t i = 0; i < rg.size(); ++i) rg[i] = float(i) * 0.25f - 7.0f;
  const std::string two = (dir / "rg.exr").string();
  ASSERT_TRUE(writeImageFloat(two, w, h, 2, rg, extras));

  Imf::InputFile a(one.c_str());
  EXPECT_EQ(a.header().compression(), Imf::ZIP_COMPRESSION);
  ASSERT_NE(a.header().channels().findChannel("Y"), nullptr);
  std::vector<float> back(depth.size());
  Imf::FrameBuffer fa;
  fa.insert("Y", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(back.data()), sizeof(float), sizeof(float) * w));
  a.setFrameBuffer(fa);
  a.readPixels(0, h - 1);
  for (size_t i = 0; i < depth.size(); ++i) {
    if (std::isnan(depth[i])) {
      EXPECT_TRUE(std::isnan(back[i]));
    } else {
      EXPECT_EQ(back[i], depth[i]) << i;
    }
  }

  Imf::InputFile b(two.c_str());
  const auto* script = b.header().findTypedAttribute<Imf::StringAttribute>("strata:script");
  const auto* seed = b.header().findTypedAttribute<Imf::IntAttribute>("strata:seed");
  ASSERT_TRUE(script && seed);
  EXPECT_EQ(script->value(), "bumps.glsl");
  EXPECT_EQ(seed->value(), 42);
  std::vector<float> r(size_t(w) * h), g(size_t(w) * h);
  Imf::FrameBuffer fb;
  fb.insert("R", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(r.data()), sizeof(float), sizeof(float) * w));
  fb.insert("G", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(g.data()), sizeof(float), sizeof(float) * w));
  b.setFrameBuffer(fb);
  b.readPixels(0, h - 1);
  for (size_t i = 0; i < r.size(); ++i) {
    EXPECT_EQ(r[i], rg[2 * i]);
    EXPECT_EQ(g[i], rg[2 * i + 1]);
  }
}

TEST(ImageIo, ColourGoesToPngOnlyAndBadCallsWriteNothing) {
  const auto dir = test::tempDir("image-io-bad");
  const std::vector<uint8_t> rgba(4 * 4 * 4, 200);
  const std::string jpg = (dir / "shot.jpg").string();
  auto st = writeImage8(jpg, 4, 4, 4, rgba);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message().find("shot.jpg: colour images are written as PNG"), std::string::npos) << st.message();
  EXPECT_FALSE(fs::exists(jpg));
  ASSERT_TRUE(writeImage8((dir / "shot.PNG").string(), 4, 4, 4, rgba));
  auto back = readImage8((dir / "shot.PNG").string());
  ASSERT_TRUE(back) << back.message();
  EXPECT_EQ(back->pixels, rgba);
  const std::string exr = (dir / "few.exr").string();
  auto few = writeImageFloat(exr, 4, 4, 1, std::vector<float>(15));
  ASSERT_FALSE(few);
  EXPECT_NE(few.message().find("few.exr: 15 floats for a 4x4x1 image"), std::string::npos) << few.message();
  EXPECT_FALSE(fs::exists(exr));
}

}  // namespace
}  // namespace strata::render
