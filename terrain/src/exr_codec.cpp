#include "exr_codec.hpp"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>
#include <OpenEXR/ImfTiledInputFile.h>
#include <OpenEXR/ImfTiledOutputFile.h>

#include <OpenEXR/Iex.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <mutex>
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

// EXR tiles inside a tile file: 64 x 64 samples (the whole level when smaller).
constexpr int kExrTile = 64;
constexpr const char* kTagAttribute = "strata:tile";

// Each field is two channels, together exactly its float32 samples: FIELD holds each sample with
// its 8 low mantissa bits cleared, which PXR24 compression (a float's sign, exponent and 15
// leftmost mantissa bits, differenced and zlib-compressed) then keeps exactly, and FIELD~low
// (UINT; '~' is not allowed in field names) holds those 8 bits, which PXR24 keeps as they are
// (it is lossless for integer channels). Integer elevations have no low bits (the channel
// compresses to almost nothing) and relief predicts better in PXR24's 24-bit form than in ZIP's
// byte planes of float32: on Rainier's int16 SRTM (a 1024^2 tile with its mips) 2.67 -> 1.99 MB,
// on the Grand Canyon's float32 DEM (512^2) 1.39 -> 0.80 MB. Tiles of the earlier layout (FIELD
// alone, ZIP) are read as they are.
std::string lowChannel(const std::string& field) { return field + "~low"; }

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

}  // namespace

std::vector<char> encodeTileExr(const std::vector<std::string>& channels,
                                const std::vector<std::vector<gis::Grid<float>>>& levels, const std::string& tag) {
  STRATA_CHECK(!levels.empty() && levels[0].size() == channels.size()) << "tile levels/channels mismatch";
  const int res = levels[0][0].width;
  Imf::Header header(res, res);
  header.compression() = Imf::PXR24_COMPRESSION;
  for (const auto& c : channels) {
    header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    header.channels().insert(lowChannel(c), Imf::Channel(Imf::UINT));
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
    std::vector<std::vector<uint32_t>> low(channels.size());
    for (int l = 0; l < out.numLevels(); ++l) {
      Imf::FrameBuffer fb;
      for (size_t c = 0; c < channels.size(); ++c) {
        const auto& g = levels[size_t(l)][c];
        STRATA_CHECK(g.width == out.levelWidth(l) && g.height == out.levelHeight(l)) << "mip level " << l << " size";
        splitLowBits(g, high[c], low[c]);
        const size_t row = size_t(g.width);
        fb.insert(channels[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(high[c].data.data()), sizeof(float),
                                          sizeof(float) * row));
        fb.insert(lowChannel(channels[c]), Imf::Slice(Imf::UINT, reinterpret_cast<char*>(low[c].data()),
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
    std::vector<gis::Grid<float>> out;
    Imf::FrameBuffer fb;
    out.reserve(channels.size());
    for (const auto& c : channels) {
      const auto* ch = in.header().channels().findChannel(c);
      if (!ch) return fail(name + ": no channel '" + c + "'");
      if (ch->type != Imf::FLOAT) return fail(name + ": channel '" + c + "' is not float32");
      out.emplace_back(w, h, 0.0f);
    }
    std::vector<std::vector<uint32_t>> low(channels.size());
    for (size_t c = 0; c < channels.size(); ++c) {
      fb.insert(channels[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(out[c].data.data()), sizeof(float),
                                        sizeof(float) * size_t(w)));
      const auto* lowCh = in.header().channels().findChannel(lowChannel(channels[c]));
      if (!lowCh) continue;  // the earlier layout: the field alone
      if (lowCh->type != Imf::UINT) return fail(name + ": channel '" + lowChannel(channels[c]) + "' is not uint32");
      low[c].assign(size_t(w) * size_t(h), 0);
      fb.insert(lowChannel(channels[c]), Imf::Slice(Imf::UINT, reinterpret_cast<char*>(low[c].data()), sizeof(uint32_t),
                                                    sizeof(uint32_t) * size_t(w)));
    }
    in.setFrameBuffer(fb);
    in.readTiles(0, in.numXTiles(level) - 1, 0, in.numYTiles(level) - 1, level);
    for (size_t c = 0; c < channels.size(); ++c) {
      for (size_t i = 0; i < low[c].size(); ++i) {
        uint32_t bits;
        std::memcpy(&bits, &out[c].data[i], sizeof bits);
        bits = (bits & ~0xffu) | (low[c][i] & 0xffu);
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
