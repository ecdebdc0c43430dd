#include "exr_codec.hpp"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>
#include <OpenEXR/ImfTiledInputFile.h>
#include <OpenEXR/ImfTiledOutputFile.h>

#include <OpenEXR/Iex.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <optional>
#include <thread>

namespace strata::terrain::detail {
namespace {

// OpenEXR streams over a byte vector.
class MemOStream : public Imf::OStream {
 public:
  MemOStream() : Imf::OStream("memory") {}
  void write(const char c[], int n) override {
    if (pos_ + uint64_t(n) > buf.size()) buf.resize(pos_ + uint64_t(n));
    std::memcpy(buf.data() + pos_, c, size_t(n));
    pos_ += uint64_t(n);
  }
  uint64_t tellp() override { return pos_; }
  void seekp(uint64_t pos) override { pos_ = pos; }
  std::vector<char> buf;

 private:
  uint64_t pos_ = 0;
};

class MemIStream : public Imf::IStream {
 public:
  MemIStream(const std::string& name, const std::vector<char>& bytes) : Imf::IStream(name.c_str()), bytes_(bytes) {}
  bool isMemoryMapped() const override { return true; }
  bool read(char c[], int n) override {
    if (pos_ + uint64_t(n) > bytes_.size()) throw IEX_NAMESPACE::InputExc("unexpected end of file");
    std::memcpy(c, bytes_.data() + pos_, size_t(n));
    pos_ += uint64_t(n);
    return pos_ < bytes_.size();
  }
  char* readMemoryMapped(int n) override {
    if (pos_ + uint64_t(n) > bytes_.size()) throw IEX_NAMESPACE::InputExc("unexpected end of file");
    char* p = const_cast<char*>(bytes_.data() + pos_);
    pos_ += uint64_t(n);
    return p;
  }
  uint64_t tellg() override { return pos_; }
  void seekg(uint64_t pos) override { pos_ = pos; }
  void clear() override {}

 private:
  const std::vector<char>& bytes_;
  uint64_t pos_ = 0;
};

// EXR tiles inside a tile file: 256 x 256 samples (the whole level when smaller). zlib (in PXR24)
// compresses each on its own: 64 x 64 (the first layouts) cost 15 % more on smooth relief.
constexpr int kExrTile = 256;
constexpr const char* kTagAttribute = "strata:tile";

// A field is stored in one of two layouts, chosen per tile from its samples; both give back every
// sample exactly (NaN as no data).
//
// Integers (every sample at every level a whole number of int32 range, or NaN; not -0): one UINT
// channel FIELD~int ('~' is not allowed in field names) under PXR24, which is lossless for
// integers and stores, per row of an EXR tile, the differences of adjacent samples in four byte
// planes. Each sample is first predicted from its west, north and north-west neighbours (W + N -
// NW, the plane through them) and the residual zigzagged (0, -1, 1, -2 -> 0, 1, 2, 3), so small
// residuals of either sign leave the high planes zero; the channel holds their running sum along
// each EXR tile row, so that PXR24's differences are exactly the zigzagged residuals. All in
// modular uint32 arithmetic: exact whatever the values. No data is the code in the attribute
// "strata:void:FIELD" (one below the smallest sample). On Rainier's int16 SRTM resampled to
// 16384^2, a 1024^2 window's level 0 takes 171 KB this way against 362 KB as float32 under PXR24
// and 364 KB in a DEFLATE GeoTIFF: PXR24's differences of the values themselves are two's
// complement, their sign spread over every byte plane.
//
// Floats: two channels, FIELD holding each sample with its 8 low mantissa bits cleared, which
// PXR24 (a float's sign, exponent and 15 leftmost mantissa bits, differenced and zlib-compressed)
// then keeps exactly, and FIELD~low (UINT) holding those 8 bits. Tiles of the first layout (FIELD
// alone, ZIP) are read as they are.
std::string lowChannel(const std::string& field) { return field + "~low"; }
std::string intChannel(const std::string& field) { return field + "~int"; }
std::string voidAttribute(const std::string& field) { return "strata:void:" + field; }

void splitLowBits(const gis::Grid<float>& g, gis::Grid<float>& high, std::vector<uint32_t>& low) {
  high = gis::Grid<float>(g.width, g.height, 0.0f);
  low.assign(g.size(), 0);
  for (size_t i = 0; i < g.size(); ++i) {
    uint32_t bits;
    std::memcpy(&bits, &g.data[i], sizeof bits);
    low[i] = bits & 0xffu;
    bits &= ~0xffu;
    std::memcpy(&high.data[i], &bits, sizeof bits);
  }
}

// Whether every sample of the channel, at every level, is NaN or a whole number an int32 holds
// (-0 is not: it would come back as +0); and the smallest whole number.
bool integral(const std::vector<std::vector<gis::Grid<float>>>& levels, size_t c, int32_t& smallest) {
  constexpr float kLimit = 2147483648.0f;  // 2^31
  smallest = INT32_MAX;
  for (const auto& level : levels) {
    for (float v : level[c].data) {
      if (std::isnan(v)) continue;
      if (!(v >= -kLimit + 128.0f && v < kLimit) || v != std::nearbyint(v) || (v == 0.0f && std::signbit(v))) {
        return false;
      }
      smallest = std::min(smallest, int32_t(v));
    }
  }
  return true;
}

uint32_t zigzag(uint32_t r) { return (r << 1) ^ uint32_t(int32_t(r) >> 31); }
uint32_t unzigzag(uint32_t z) { return (z >> 1) ^ (0u - (z & 1u)); }

// The prediction of sample (x, y) from the samples before it (row-major): W + N - NW inside, the
// one neighbour on the first row and column, 0 at the origin.
uint32_t predict(const std::vector<uint32_t>& q, size_t w, size_t x, size_t y) {
  if (y == 0) return x == 0 ? 0u : q[x - 1];
  if (x == 0) return q[(y - 1) * w];
  return q[y * w + x - 1] + q[(y - 1) * w + x] - q[(y - 1) * w + x - 1];
}

// A level of an integer channel as the UINT samples to hand to PXR24 (see above): the running
// sums restart at each EXR tile's first column, where PXR24's differences do.
std::vector<uint32_t> integerSamples(const gis::Grid<float>& g, uint32_t voidCode, size_t tileWidth) {
  const size_t w = size_t(g.width);
  std::vector<uint32_t> q(g.size()), out(g.size());
  for (size_t i = 0; i < g.size(); ++i) q[i] = std::isnan(g.data[i]) ? voidCode : uint32_t(int32_t(g.data[i]));
  for (size_t y = 0; y < size_t(g.height); ++y) {
    for (size_t x = 0; x < w; ++x) {
      const uint32_t z = zigzag(q[y * w + x] - predict(q, w, x, y));
      out[y * w + x] = x % tileWidth == 0 ? z : out[y * w + x - 1] + z;
    }
  }
  return out;
}

// The inverse of integerSamples, in place into `g`.
void integerValues(const std::vector<uint32_t>& in, uint32_t voidCode, size_t tileWidth, gis::Grid<float>& g) {
  const size_t w = size_t(g.width);
  std::vector<uint32_t> q(g.size());
  for (size_t y = 0; y < size_t(g.height); ++y) {
    for (size_t x = 0; x < w; ++x) {
      const size_t i = y * w + x;
      const uint32_t z = x % tileWidth == 0 ? in[i] : in[i] - in[i - 1];
      q[i] = unzigzag(z) + predict(q, w, x, y);
      g.data[i] = q[i] == voidCode ? gis::kNoData : float(int32_t(q[i]));
    }
  }
}

}  // namespace

std::vector<char> encodeTileExr(const std::vector<std::string>& channels,
                                const std::vector<std::vector<gis::Grid<float>>>& levels, const std::string& tag) {
  STRATA_CHECK(!levels.empty() && levels[0].size() == channels.size()) << "tile levels/channels mismatch";
  const int res = levels[0][0].width;
  Imf::Header header(res, res);
  header.compression() = Imf::PXR24_COMPRESSION;
  // Per field: its void code when stored as integers (see above), else float.
  std::vector<std::optional<uint32_t>> voidCode(channels.size());
  for (size_t c = 0; c < channels.size(); ++c) {
    int32_t smallest = 0;
    if (integral(levels, c, smallest)) {
      voidCode[c] = uint32_t(smallest - 1);
      header.channels().insert(intChannel(channels[c]), Imf::Channel(Imf::UINT));
      header.insert(voidAttribute(channels[c]), Imf::IntAttribute(int(smallest - 1)));
    } else {
      header.channels().insert(channels[c], Imf::Channel(Imf::FLOAT));
      header.channels().insert(lowChannel(channels[c]), Imf::Channel(Imf::UINT));
    }
  }
  const int ts = std::min(res, kExrTile);
  header.setTileDescription(Imf::TileDescription(ts, ts, Imf::MIPMAP_LEVELS, Imf::ROUND_DOWN));
  header.insert(kTagAttribute, Imf::StringAttribute(tag));
  MemOStream os;
  {
    // In parallel on the global pool's threads while an EncodeThreads lives, else on this one.
    Imf::TiledOutputFile out(os, header, std::max(1, Imf::globalThreadCount()));
    STRATA_CHECK(out.numLevels() == int(levels.size()))
        << out.numLevels() << " EXR levels, " << levels.size() << " given";
    std::vector<gis::Grid<float>> high(channels.size());
    std::vector<std::vector<uint32_t>> words(channels.size());  // the low bits, or the integer samples
    for (int l = 0; l < out.numLevels(); ++l) {
      Imf::FrameBuffer fb;
      for (size_t c = 0; c < channels.size(); ++c) {
        const auto& g = levels[size_t(l)][c];
        STRATA_CHECK(g.width == out.levelWidth(l) && g.height == out.levelHeight(l)) << "mip level " << l << " size";
        const size_t row = size_t(g.width);
        if (voidCode[c]) {
          words[c] = integerSamples(g, *voidCode[c], size_t(ts));
          fb.insert(intChannel(channels[c]), Imf::Slice(Imf::UINT, reinterpret_cast<char*>(words[c].data()),
                                                        sizeof(uint32_t), sizeof(uint32_t) * row));
          continue;
        }
        splitLowBits(g, high[c], words[c]);
        fb.insert(channels[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(high[c].data.data()), sizeof(float),
                                          sizeof(float) * row));
        fb.insert(lowChannel(channels[c]), Imf::Slice(Imf::UINT, reinterpret_cast<char*>(words[c].data()),
                                                      sizeof(uint32_t), sizeof(uint32_t) * row));
      }
      out.setFrameBuffer(fb);
      out.writeTiles(0, out.numXTiles(l) - 1, 0, out.numYTiles(l) - 1, l);
    }
  }
  return std::move(os.buf);
}

EncodeThreads::EncodeThreads() {
  static std::mutex m;
  std::lock_guard lock(m);
  if (Imf::globalThreadCount() != 0) return;
  Imf::setGlobalThreadCount(int(std::max(1u, std::thread::hardware_concurrency())));
  started_ = true;
}

EncodeThreads::~EncodeThreads() {
  if (started_) Imf::setGlobalThreadCount(0);  // joins the pool's threads
}

Result<std::vector<gis::Grid<float>>> decodeTileExrLevel(const std::string& name, const std::vector<char>& bytes,
                                                         const std::vector<std::string>& channels, int level) {
  try {
    MemIStream is(name, bytes);
    Imf::TiledInputFile in(is, 1);
    if (in.levelMode() != Imf::MIPMAP_LEVELS) return fail(name + ": not a MIP-mapped tile");
    if (level < 0 || level >= in.numLevels()) {
      return fail(name + ": no mip level " + std::to_string(level) + " (has " + std::to_string(in.numLevels()) + ")");
    }
    const int w = in.levelWidth(level), h = in.levelHeight(level);
    const auto& list = in.header().channels();
    auto isType = [&](const std::string& ch, Imf::PixelType type) -> Status {
      if (list.findChannel(ch)->type == type) return {};
      return fail(name + ": channel '" + ch + "' is not " + (type == Imf::FLOAT ? "float32" : "uint32"));
    };
    std::vector<gis::Grid<float>> out;
    std::vector<std::vector<uint32_t>> words(channels.size());  // the low bits, or the integer samples
    std::vector<std::optional<uint32_t>> voidCode(channels.size());
    Imf::FrameBuffer fb;
    out.reserve(channels.size());
    for (size_t c = 0; c < channels.size(); ++c) {
      out.emplace_back(w, h, 0.0f);
      const size_t row = size_t(w);
      if (list.findChannel(intChannel(channels[c]))) {
        STRATA_TRY_STATUS(isType(intChannel(channels[c]), Imf::UINT));
        const auto* code = in.header().findTypedAttribute<Imf::IntAttribute>(voidAttribute(channels[c]));
        if (!code) return fail(name + ": integer channel '" + channels[c] + "' has no void code");
        voidCode[c] = uint32_t(code->value());
        words[c].assign(size_t(w) * size_t(h), 0);
        fb.insert(intChannel(channels[c]), Imf::Slice(Imf::UINT, reinterpret_cast<char*>(words[c].data()),
                                                      sizeof(uint32_t), sizeof(uint32_t) * row));
        continue;
      }
      if (!list.findChannel(channels[c])) return fail(name + ": no channel '" + channels[c] + "'");
      STRATA_TRY_STATUS(isType(channels[c], Imf::FLOAT));
      fb.insert(channels[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(out[c].data.data()), sizeof(float),
                                        sizeof(float) * row));
      if (!list.findChannel(lowChannel(channels[c]))) continue;  // the first layout: the field alone
      STRATA_TRY_STATUS(isType(lowChannel(channels[c]), Imf::UINT));
      words[c].assign(size_t(w) * size_t(h), 0);
      fb.insert(lowChannel(channels[c]), Imf::Slice(Imf::UINT, reinterpret_cast<char*>(words[c].data()),
                                                    sizeof(uint32_t), sizeof(uint32_t) * row));
    }
    in.setFrameBuffer(fb);
    in.readTiles(0, in.numXTiles(level) - 1, 0, in.numYTiles(level) - 1, level);
    for (size_t c = 0; c < channels.size(); ++c) {
      if (voidCode[c]) {
        integerValues(words[c], *voidCode[c], size_t(in.tileXSize()), out[c]);
        continue;
      }
      for (size_t i = 0; i < words[c].size(); ++i) {
        uint32_t bits;
        std::memcpy(&bits, &out[c].data[i], sizeof bits);
        bits = (bits & ~0xffu) | (words[c][i] & 0xffu);
        std::memcpy(&out[c].data[i], &bits, sizeof bits);
      }
    }
    return out;
  } catch (const std::exception& e) {
    return fail(name + ": " + e.what());
  }
}

Result<std::string> decodeTileExrTag(const std::string& name, const std::vector<char>& bytes) {
  try {
    MemIStream is(name, bytes);
    Imf::TiledInputFile in(is, 1);
    const auto* tag = in.header().findTypedAttribute<Imf::StringAttribute>(kTagAttribute);
    return tag ? tag->value() : std::string();
  } catch (const std::exception& e) {
    return fail(name + ": " + e.what());
  }
}

}  // namespace strata::terrain::detail
