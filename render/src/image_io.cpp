#include <strata/render/image_io.hpp>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <exception>

namespace strata::render {
namespace {

std::string sizeText(int width, int height, int channels) {
  return std::to_string(width) + "x" + std::to_string(height) + "x" + std::to_string(channels);
}

}  // namespace

Status writeImageFloat(const std::string& path, int width, int height, int channels, std::span<const float> pixels,
                       const ExrExtras& extras) {
  if (width <= 0 || height <= 0 || channels < 1 || channels > 4) {
    return fail(path + ": an EXR here needs a size and 1-4 channels, not " + sizeText(width, height, channels));
  }
  if (pixels.size() != size_t(width) * size_t(height) * size_t(channels)) {
    return fail(path + ": " + std::to_string(pixels.size()) + " floats for a " + sizeText(width, height, channels) +
                " image");
  }
  std::vector<std::string> names = extras.channelNames;
  if (names.empty())
    names = channels == 1 ? std::vector<std::string>{"Y"} : std::vector<std::string>{"R", "G", "B", "A"};
  if (names.size() < size_t(channels)) return fail(path + ": " + std::to_string(channels) + " channels, fewer names");
  names.resize(size_t(channels));
  try {
    Imf::Header header(width, height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const auto& [key, value] : extras.strings) header.insert(key, Imf::StringAttribute(value));
    for (const auto& [key, value] : extras.ints) header.insert(key, Imf::IntAttribute(value));
    Imf::FrameBuffer frame;
    const size_t xStride = sizeof(float) * size_t(channels), yStride = xStride * size_t(width);
    for (int c = 0; c < channels; ++c) {
      header.channels().insert(names[size_t(c)], Imf::Channel(Imf::FLOAT));
      frame.insert(names[size_t(c)],
                   Imf::Slice(Imf::FLOAT, const_cast<char*>(reinterpret_cast<const char*>(pixels.data() + c)), xStride,
                              yStride));
    }
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(frame);
    file.writePixels(height);
  } catch (const std::exception& e) {
    return fail(path + ": cannot write the EXR: " + e.what());
  }
  return {};
}

}  // namespace strata::render
