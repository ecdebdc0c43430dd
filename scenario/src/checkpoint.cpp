#include "checkpoint.hpp"

#include <charconv>

#include <strata/core/bytes.hpp>
#include <strata/sim/state_codec.hpp>

#include <cstring>
#include <fstream>
#include <sstream>
#include <type_traits>

#ifndef STRATA_VERSION
#define STRATA_VERSION "unknown"
#endif

namespace strata::scenario {
namespace {

constexpr char kMagic[8] = {'S', 'T', 'R', 'A', 'T', 'A', 'C', '8'};  // 8: the depth error (W34)

}  // namespace

uint64_t fnv1a(std::string_view text) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
  return h;
}

std::string encodeCheckpoint(const CheckpointOwner& owner, const Checkpoint& c) {
  ByteWriter w;
  w.out.append(kMagic, sizeof kMagic);
  w.str(STRATA_VERSION);
  w.str(owner.command);
  w.pod(owner.scenarioHash);
  w.pod(int32_t(c.interval));
  w.pod(c.wallS);
  w.vec(c.series);
  w.pod(c.spinUp);
  w.vec(c.probes);
  w.str(sim::encodeState(c.state));
  w.pod(fnv1a(w.out));
  return w.out;
}

Result<Checkpoint> decodeCheckpoint(const std::filesystem::path& path, const CheckpointOwner& owner) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return fail(path.string() + ": cannot read the checkpoint");
  std::stringstream ss;
  ss << f.rdbuf();
  const std::string data = ss.str();
  if (data.size() < sizeof kMagic + 8 || std::memcmp(data.data(), kMagic, sizeof kMagic) != 0) {
    return fail(path.string() + ": not a Strata checkpoint (or one of an older format)");
  }
  uint64_t sum = 0;
  std::memcpy(&sum, data.data() + data.size() - 8, 8);
  const std::string_view body(data.data(), data.size() - 8);
  if (fnv1a(body) != sum) return fail(path.string() + ": the checkpoint is damaged (its checksum does not match)");
  ByteReader r{body, sizeof kMagic};
  std::string version, command;
  uint64_t hash = 0;
  int32_t interval = 0;
  r.str(version);
  r.str(command);
  r.pod(hash);
  r.pod(interval);
  if (!r.ok) return fail(path.string() + ": truncated checkpoint");
  if (version != STRATA_VERSION) {
    return fail(path.string() + ": written by Strata " + version + ", this is " + STRATA_VERSION +
                "; run again without --resume");
  }
  if (command != owner.command) {
    return fail(path.string() + ": written by `strata " + command + "`, not `strata " + owner.command + "`");
  }
  if (hash != owner.scenarioHash) return fail(path.string() + ": written by a different scenario (the file changed)");
  Checkpoint c;
  c.interval = interval;
  r.pod(c.wallS);
  r.vec(c.series);
  r.pod(c.spinUp);
  r.vec(c.probes);
  std::string state;
  r.str(state);
  if (!r.ok || r.at != body.size() || c.interval < 0 || !(c.wallS >= 0)) {
    return fail(path.string() + ": truncated or corrupt checkpoint");
  }
  auto decoded = sim::decodeState(state);
  if (!decoded) return fail(path.string() + ": corrupt checkpoint (" + decoded.message() + ")");
  c.state = std::move(decoded).value();
  return c;
}

std::string rankCheckpointFile(int rank, int ranks, bool previous) {
  return "checkpoint." + std::to_string(rank) + "-of-" + std::to_string(ranks) + (previous ? ".previous" : "") + ".bin";
}

bool isRankCheckpointFile(std::string_view name, int* ranks) {
  // "checkpoint." + at least "0-of-1" + ".bin" (checkpoint.bin, the one process's, is not one).
  if (name.size() < 21 || !name.starts_with("checkpoint.") || !name.ends_with(".bin")) return false;
  name.remove_prefix(11);
  name.remove_suffix(4);
  if (name.ends_with(".previous")) name.remove_suffix(9);
  const auto of = name.find("-of-");
  if (of == std::string_view::npos) return false;
  int r = -1, n = 0;
  const auto a = name.substr(0, of), b = name.substr(of + 4);
  const auto ra = std::from_chars(a.data(), a.data() + a.size(), r);
  const auto rb = std::from_chars(b.data(), b.data() + b.size(), n);
  if (ra.ec != std::errc() || ra.ptr != a.data() + a.size() || rb.ec != std::errc() || rb.ptr != b.data() + b.size())
    return false;
  if (!(r >= 0 && n >= 1 && r < n) ||
      rankCheckpointFile(r, n) != std::string("checkpoint.") + std::string(name) + ".bin")
    return false;
  if (ranks) *ranks = n;
  return true;
}

}  // namespace strata::scenario
