#pragma once
// Private: tile files as multi-channel, MIP-mapped, tiled OpenEXR images, each float32 field
// kept exactly as a PXR24-compressed channel and its low 8 bits (exr_codec.cpp), held in memory
// (so the checksum covers exactly the bytes written and read). Keeps OpenEXR's headers out of the
// public ones.

#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>

namespace strata::terrain::detail {

/// Encodes one tile: `levels[l][c]` is channel c at mip level l (level 0 square, each next level
/// half the side, down to 1x1). Channel names must be valid EXR names without '.'. `tag` is
/// stored as the string attribute "strata:tile" (where the tile belongs; `strata check` compares
/// it with the manifest).
std::vector<char> encodeTileExr(const std::vector<std::string>& channels,
                                const std::vector<std::vector<gis::Grid<float>>>& levels, const std::string& tag);

/// While one lives, encodeTileExr compresses a tile's EXR tiles on OpenEXR's global thread pool,
/// one thread per core (PXR24 runs zlib at its default level: an ingest's main cost). The pool is
/// emptied again when it dies, so no pool thread outlives the work (they would not survive a
/// fork(): a forked child that encodes would wait for them forever). Does nothing where the pool
/// already has threads (another user set them).
class EncodeThreads {
 public:
  EncodeThreads();
  ~EncodeThreads();
  EncodeThreads(const EncodeThreads&) = delete;
  EncodeThreads& operator=(const EncodeThreads&) = delete;

 private:
  bool started_ = false;
};

/// The "strata:tile" attribute of a tile file (empty when it has none).
Result<std::string> decodeTileExrTag(const std::string& name, const std::vector<char>& bytes);

/// Decodes mip level `level` of every channel in `channels` (in that order). `name` is used in
/// error messages. Fails when the bytes are not such a tile, or the level or a channel is missing.
Result<std::vector<gis::Grid<float>>> decodeTileExrLevel(const std::string& name, const std::vector<char>& bytes,
                                                         const std::vector<std::string>& channels, int level);

}  // namespace strata::terrain::detail
