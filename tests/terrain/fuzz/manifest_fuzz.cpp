// libFuzzer target over the tile store's manifest reader: the input bytes are a manifest's text
// and go through parseManifest (the screen for toml++'s defects, toml++'s parser, every key's
// checks). A manifest it accepts must write back (manifestToToml) to text that reads back to the
// same text: the writer and the reader agree on everything the reader lets through. Built and
// run by scripts/fuzz.sh with toml++ compiled in, header-only, with its assertions on, so an
// input that reaches one of toml++ 3.3.0's defects aborts instead of passing unnoticed.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "manifest.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto m = strata::terrain::detail::parseManifest(text, "fuzz.toml");
  if (!m.ok()) return 0;
  const std::string once = strata::terrain::detail::manifestToToml(*m);
  auto again = strata::terrain::detail::parseManifest(once, "rewritten.toml");
  if (!again.ok() || strata::terrain::detail::manifestToToml(*again) != once) std::abort();
  return 0;
}
