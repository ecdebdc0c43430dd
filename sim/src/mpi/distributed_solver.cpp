#include <strata/sim/mpi/distributed_solver.hpp>

#include <algorithm>
#include <climits>
#include <cstring>
#include <string>
#include <utility>

#include <strata/sim/state_codec.hpp>

#include <strata/sim/exact_sum.hpp>
#include <strata/sim/mpi/ranks.hpp>
#include "decomposition.hpp"
#include "tile_common.hpp"

namespace strata::sim {

using detail::BlockGrid;
using detail::HaloPiece;

namespace {

// Block solvers' coordinates are their extent's: global cell (x, y) is (x - e.x, y - e.y).
CellRect intersect(const CellRect& a, const CellRect& b) { return a.intersected(b); }
bool inside(const CellRect& r, int x, int y) { return x >= r.x && y >= r.y && x < r.x + r.width && y < r.y + r.height; }

bool allZeroBits(const float* v, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    uint32_t bits;
    std::memcpy(&bits, &v[i], 4);
    if (bits != 0) return false;
  }
  return true;
}

// Floats per cell of the parts of a block that `parts` asks for (the diagonal flux with `diag`),
// in CellBlock's order: what pack() writes per cell.
size_t floatsPerCell(unsigned parts, bool diag, int layers) {
  size_t n = 0;
  const CellBlock none;
  int k = 0;
  CellBlock::forEachPart(none, layers, [&](unsigned bit, const std::vector<float>&, size_t per, size_t planes) {
    const bool isDiag = k++ == 2;
    if ((parts & bit) && (!isDiag || diag)) n += per * planes;
  });
  return n;
}

// The parts `b` has, one after the other (each as the block holds it).
void pack(const CellBlock& b, std::vector<float>& out) {
  CellBlock::forEachPart(
      b, 0, [&](unsigned, const std::vector<float>& v, size_t, size_t) { out.insert(out.end(), v.begin(), v.end()); });
}

// The parts of a `rect` block read from `in` (as pack() wrote it); returns the floats used.
size_t unpack(const float* in, const CellRect& rect, unsigned parts, bool diag, int layers, CellBlock& b) {
  b = CellBlock{.rect = rect};
  const size_t cells = b.cells();
  size_t at = 0;
  int k = 0;
  CellBlock::forEachPart(b, layers, [&](unsigned bit, std::vector<float>& v, size_t per, size_t planes) {
    const bool isDiag = k++ == 2;
    if (!(parts & bit) || (isDiag && !diag)) return;
    v.assign(in + at, in + at + per * planes * cells);
    at += per * planes * cells;
  });
  return at;
}

class Timer {
 public:
  explicit Timer(double& sink) : sink_(sink), t0_(MPI_Wtime()) {}
  ~Timer() { sink_ += MPI_Wtime() - t0_; }
  Timer(const Timer&) = delete;
  Timer& operator=(const Timer&) = delete;

 private:
  double& sink_;
  double t0_;
};

}  // namespace

// -------------------------------------------------------------------------------------------------

struct DistributedSolver::Impl {
  struct Block {
    int id = 0;
    CellRect interior, extent;
    std::unique_ptr<Solver> solver;
    bool eligible = true;  // no rain raster, source or level touches its extent
    bool idle = false;     // skips its passes this step
    bool skippedLast = false;
    bool wake = false;  // a halo piece brought water or motion: active next step
    long long recheckAfter = 0;
    double speed = 0;  // wave speed cached for the step count speedStep
    long long speedStep = -1;
    std::vector<float> rainInterior;  // raster (mm/h) over the interior; empty: none
    // Global cell (x, y) in the block solver's coordinates.
    CellRect local(const CellRect& r) const { return {r.x - extent.x, r.y - extent.y, r.width, r.height}; }
  };
  struct Message {
    int peer = 0, tag = 0;
    std::vector<HaloPiece> pieces;  // in (src, dst) order
    size_t floats = 0;
    std::vector<float> buffer;
    MPI_Request request = MPI_REQUEST_NULL;
  };

  MPI_Comm comm = MPI_COMM_NULL;
  int rank = 0, size = 1;
  DistributedOptions options;
  SolverFactory make;
  RegionSource region;
  BlockGrid grid;
  std::vector<int> order, owner;
  std::vector<HaloPiece> pieces;
  std::vector<Block> blocks;                // this rank's, by id
  std::vector<int> localIndex;              // per block: index in `blocks`, or -1
  std::vector<std::vector<Message>> sends;  // per local block
  std::vector<Message> receives;
  std::vector<HaloPiece> localCopies;
  std::vector<int> stepOrder;  // local block indices: those that send to other ranks first
  DistributedCounters counters;
  std::string blockBackend;
  int tagMove = 0;

  ~Impl() {
    if (comm != MPI_COMM_NULL) {
      int finalized = 0;
      MPI_Finalized(&finalized);
      if (!finalized) MPI_Comm_free(&comm);
    }
  }

  bool diag(const SimParams& p) const { return p.diagonalPipes; }
  int layers() const { return int(region.materials.size()); }
  unsigned halo = 0;  // the parts halos carry (haloParts), as plan() last sized the messages
  size_t haloFloats(const SimParams& p) const { return floatsPerCell(haloParts(p), diag(p), layers()); }
  Block& block(int id) { return blocks[size_t(localIndex[size_t(id)])]; }
  const Block& block(int id) const { return blocks[size_t(localIndex[size_t(id)])]; }
  bool mine(int id) const { return localIndex[size_t(id)] >= 0; }
  const Block& holding(const CellRect& rect) const;

  SimParams blockParams(const SimParams& p, const CellRect& e) const {
    SimParams sp = p;
    sp.openEdges = detail::tileOpenEdges(p.openEdges, e.x, e.y, e.x + e.width, e.y + e.height, grid.width, grid.height);
    return sp;
  }

  // Makes block `id`'s solver from the region's window, with the run's sources and levels.
  Result<Block> build(int id, const SimParams& params, const std::vector<Source>& sources,
                      const std::vector<LevelBoundary>& levels, float wetThresholdM) const {
    Block b;
    b.id = id;
    b.interior = grid.interior(id);
    b.extent = grid.extent(id);
    STRATA_TRY(auto input, readWindow(region, b.extent));
    for (float r : input.rainMmPerHour.data) b.eligible = b.eligible && !(r > 0.0f);
    if (input.rainMmPerHour.size() > 0) {
      const CellRect li = b.local(b.interior);
      for (int y = 0; y < li.height; ++y) {
        for (int x = 0; x < li.width; ++x) b.rainInterior.push_back(input.rainMmPerHour.at(li.x + x, li.y + y));
      }
    }
    STRATA_TRY(b.solver, make(input, blockParams(params, b.extent)));
    for (const auto& s : sources) STRATA_TRY_STATUS(addSource(b, s));
    for (const auto& l : levels) STRATA_TRY_STATUS(addLevel(b, l));
    if (wetThresholdM >= 0) b.solver->enableFloodStats(wetThresholdM);
    return b;
  }

  // Each cell of a source becomes its own source carrying its share (as TiledSolver), so a block
  // that sees only some of the cells feeds each the right amount.
  static Status addSource(Block& b, const Source& source) {
    for (auto one : detail::perCellSources(source)) {
      const auto [x, y] = one.cells[0];
      if (!inside(b.extent, x, y)) continue;
      one.cells = {{x - b.extent.x, y - b.extent.y}};
      STRATA_TRY_STATUS(b.solver->addSource(one));
      b.eligible = false;
    }
    return {};
  }
  static Status addLevel(Block& b, const LevelBoundary& level) {
    LevelBoundary sub{{}, level.stageM};
    for (auto [x, y] : level.cells) {
      if (inside(b.extent, x, y)) sub.cells.push_back({x - b.extent.x, y - b.extent.y});
    }
    if (sub.cells.empty()) return {};
    b.eligible = false;
    return b.solver->addLevel(sub);
  }

  // Builds the blocks `owner` gives this rank that it does not hold, and drops those it no longer
  // owns (their states must have been taken already). Collective status.
  Status adoptOwners(const SimParams& params, const std::vector<Source>& sources,
                     const std::vector<LevelBoundary>& levels, float wetThresholdM, std::vector<Block> arrived) {
    std::vector<Block> next;
    Status status;
    for (int id = 0; id < grid.count(); ++id) {
      if (owner[size_t(id)] != rank) continue;
      if (mine(id)) {
        next.push_back(std::move(block(id)));
        continue;
      }
      auto it = std::find_if(arrived.begin(), arrived.end(), [id](const Block& b) { return b.id == id; });
      if (it != arrived.end()) {
        next.push_back(std::move(*it));
        continue;
      }
      auto b = build(id, params, sources, levels, wetThresholdM);
      if (!b) {
        status = fail("block " + std::to_string(id) + ": " + b.message());
        break;
      }
      next.push_back(std::move(b).value());
    }
    blocks = std::move(next);
    localIndex.assign(size_t(grid.count()), -1);
    for (size_t k = 0; k < blocks.size(); ++k) localIndex[size_t(blocks[k].id)] = int(k);
    if (blockBackend.empty() && !blocks.empty()) blockBackend = blocks[0].solver->backendName();
    plan(params);
    return Ranks::of(comm).agree(status);
  }

  // Who sends what to whom each step, from `owner`.
  void plan(const SimParams& params) {
    sends.assign(blocks.size(), {});
    receives.clear();
    localCopies.clear();
    halo = haloParts(params);
    const size_t per = haloFloats(params);
    for (const auto& p : pieces) {
      const bool src = mine(p.src), dst = mine(p.dst);
      if (src && dst) {
        localCopies.push_back(p);
      } else if (src) {
        auto& list = sends[size_t(localIndex[size_t(p.src)])];
        const int peer = owner[size_t(p.dst)];
        auto it = std::find_if(list.begin(), list.end(), [peer](const Message& m) { return m.peer == peer; });
        if (it == list.end()) it = list.insert(list.end(), Message{peer, p.src, {}, 0, {}, MPI_REQUEST_NULL});
        it->pieces.push_back(p);
        it->floats += per * size_t(p.rect.width) * size_t(p.rect.height);
      } else if (dst) {
        if (receives.empty() || receives.back().tag != p.src) {
          receives.push_back(Message{owner[size_t(p.src)], p.src, {}, 0, {}, MPI_REQUEST_NULL});
        }
        receives.back().pieces.push_back(p);
        receives.back().floats += per * size_t(p.rect.width) * size_t(p.rect.height);
      }
    }
    for (auto& list : sends) {
      std::sort(list.begin(), list.end(), [](const Message& a, const Message& b) { return a.peer < b.peer; });
    }
    // Blocks whose halos go to other ranks step first: their messages travel while the others compute.
    stepOrder.clear();
    for (size_t k = 0; k < blocks.size(); ++k) {
      if (!sends[k].empty()) stepOrder.push_back(int(k));
    }
    for (size_t k = 0; k < blocks.size(); ++k) {
      if (sends[k].empty()) stepOrder.push_back(int(k));
    }
  }

  // Idle: skipping the step is exact when every value a step reads is zero: the extent's state and
  // fluxes (so no water, no motion), the interior's compensation terms (kahanAdd of 0 leaves a sum
  // unchanged only when its error term is 0), with no rain, source, level or thermal weathering.
  bool canIdle(const Block& b, const SimParams& p) const {
    return options.skipIdle && b.eligible && !(p.rainMmPerHour > 0.0f) && !p.thermalEnabled;
  }
  bool stillAndDry(const Block& b) const {
    const CellRect all{0, 0, b.extent.width, b.extent.height};
    const CellBlock e = b.solver->readBlock(all.x, all.y, all.width, all.height, kBlockState | kBlockFlux);
    if (!allZeroBits(e.state.data(), e.state.size()) || !allZeroBits(e.flux.data(), e.flux.size()) ||
        !allZeroBits(e.fluxDiag.data(), e.fluxDiag.size())) {
      return false;
    }
    const CellRect li = b.local(b.interior);
    const CellBlock a = b.solver->readBlock(li.x, li.y, li.width, li.height, kBlockAccum);
    for (size_t i = 0; i < a.cells(); ++i) {
      for (int k = 1; k < kAccumDepthError; k += 2) {  // the sums' errors
        if (!allZeroBits(&a.accum[kAccumPerCell * i + size_t(k)], 1)) return false;
      }
      if (!allZeroBits(&a.accum[kAccumPerCell * i + kAccumDepthError], 1)) return false;
    }
    return true;
  }
  void decideIdle(Block& b, const SimParams& p) {
    if (!canIdle(b, p)) {
      b.idle = false;
    } else if (b.idle) {
      if (b.wake) b.idle = false;
    } else if (counters.steps >= b.recheckAfter) {
      const double speed = b.speedStep == counters.steps ? b.speed : b.solver->maxWaveSpeedMS();
      if (speed == 0.0) {
        b.idle = stillAndDry(b);
        if (!b.idle) b.recheckAfter = counters.steps + 8;  // e.g. a dried cell's compensation term
      }
    }
    b.wake = false;
  }
  void noteIncoming(Block& dst, const CellBlock& piece) {
    if (dst.idle && !dst.wake) {
      dst.wake = !allZeroBits(piece.state.data(), piece.state.size()) ||
                 !allZeroBits(piece.flux.data(), piece.flux.size()) ||
                 !allZeroBits(piece.fluxDiag.data(), piece.fluxDiag.size());
    }
  }
  void invalidate() {
    for (auto& b : blocks) {
      b.idle = false;
      b.wake = false;
      b.recheckAfter = 0;
      b.speedStep = -1;
    }
  }

  void exchangeStart() {
    for (auto& m : receives) {
      m.buffer.resize(m.floats);
      MPI_Irecv(m.buffer.data(), int(m.floats), MPI_FLOAT, m.peer, m.tag, comm, &m.request);
    }
  }
  void send(size_t k) {
    const Block& b = blocks[k];
    for (auto& m : sends[k]) {
      m.buffer.clear();
      m.buffer.reserve(m.floats);
      for (const auto& p : m.pieces) {
        const CellRect r = b.local(p.rect);
        pack(b.solver->readBlock(r.x, r.y, r.width, r.height, halo), m.buffer);
      }
      STRATA_CHECK(m.buffer.size() == m.floats)
          << "halo message of " << m.buffer.size() << " floats, planned " << m.floats;
      MPI_Isend(m.buffer.data(), int(m.floats), MPI_FLOAT, m.peer, m.tag, comm, &m.request);
      counters.haloBytesSent += double(m.floats) * 4.0;
      ++counters.messagesSent;
    }
  }
  void exchangeFinish(const SimParams& params) {
    for (const auto& p : localCopies) {
      const Block& s = block(p.src);
      Block& d = block(p.dst);
      const CellRect r = s.local(p.rect);
      CellBlock piece = s.solver->readBlock(r.x, r.y, r.width, r.height, halo);
      piece.rect.x = p.rect.x - d.extent.x;
      piece.rect.y = p.rect.y - d.extent.y;
      noteIncoming(d, piece);
      d.solver->writeBlock(piece);
      counters.haloBytesLocal += double(haloFloats(params)) * 4.0 * double(piece.cells());
    }
    std::vector<MPI_Request> requests;
    for (auto& m : receives) requests.push_back(m.request);
    for (size_t n = 0; n < requests.size(); ++n) {
      int k = MPI_UNDEFINED;
      {
        Timer timer(counters.waitSeconds);
        MPI_Waitany(int(requests.size()), requests.data(), &k, MPI_STATUS_IGNORE);
      }
      Message& m = receives[size_t(k)];
      size_t at = 0;
      for (const auto& p : m.pieces) {
        Block& d = block(p.dst);
        CellBlock piece;
        at += unpack(m.buffer.data() + at, d.local(p.rect), halo, diag(params), layers(), piece);
        noteIncoming(d, piece);
        d.solver->writeBlock(piece);
      }
    }
    Timer timer(counters.waitSeconds);
    for (auto& list : sends) {
      for (auto& m : list) MPI_Wait(&m.request, MPI_STATUS_IGNORE);
    }
  }
  // Lets messages already sent move on while blocks compute (MPI progresses inside MPI calls).
  void progress() {
    for (auto& list : sends) {
      for (auto& m : list) {
        int done = 0;
        if (m.request != MPI_REQUEST_NULL) MPI_Test(&m.request, &done, MPI_STATUS_IGNORE);
      }
    }
  }

  // The pieces of `rect` this rank owns, gathered on rank 0 into one block (collective).
  CellBlock gather(const CellRect& rect, unsigned parts, const SimParams& params) const {
    std::vector<float> mine;
    for (const auto& b : blocks) {
      const CellRect r = intersect(rect, b.interior);
      if (r.empty()) continue;
      const CellRect l = b.local(r);
      mine.insert(mine.end(), {float(r.x), float(r.y), float(r.width), float(r.height)});
      pack(b.solver->readBlock(l.x, l.y, l.width, l.height, parts), mine);
    }
    const std::vector<float> all = gatherv(mine);
    CellBlock out{.rect = rect};
    if (rank != 0) return out;
    const size_t cells = out.cells();
    if (parts & kBlockState) out.state.resize(4 * cells);
    if (parts & kBlockFlux) out.flux.resize(4 * cells);
    if ((parts & kBlockFlux) && diag(params)) out.fluxDiag.resize(4 * cells);
    if (parts & kBlockLayers) out.layers.resize(size_t(layers()) * cells);
    if (parts & kBlockAccum) out.accum.resize(kAccumPerCell * cells);
    if (parts & kBlockCarried) out.carried.resize(kAccumCarried * cells);
    for (size_t at = 0; at < all.size();) {
      const CellRect r{int(all[at]), int(all[at + 1]), int(all[at + 2]), int(all[at + 3])};
      CellBlock piece;
      at += 4 + unpack(all.data() + at + 4, r, parts, diag(params), layers(), piece);
      copyOverlap(piece, out, layers());
    }
    return out;
  }
  // Every rank's floats, concatenated in rank order on rank 0 (collective).
  std::vector<float> gatherv(const std::vector<float>& mine) const {
    STRATA_CHECK(mine.size() < size_t(INT_MAX)) << "a rank's part of a gather exceeds 2^31 floats";
    int n = int(mine.size());
    std::vector<int> counts(static_cast<size_t>(size)), offsets(static_cast<size_t>(size));
    MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
    std::vector<float> all;
    if (rank == 0) {
      size_t total = 0;
      for (int r = 0; r < size; ++r) {
        offsets[size_t(r)] = int(total);
        total += size_t(counts[size_t(r)]);
      }
      STRATA_CHECK(total < size_t(INT_MAX)) << "a gather to rank 0 exceeds 2^31 floats";
      all.resize(total);
    }
    MPI_Gatherv(mine.data(), n, MPI_FLOAT, all.data(), counts.data(), offsets.data(), MPI_FLOAT, 0, comm);
    return all;
  }
  // `perCell` floats per cell of the whole grid on rank 0, each block giving its interior's
  // (row-major, interleaved) through `read` (collective).
  template <class F>
  std::vector<float> gatherCells(int perCell, F&& read) const {
    std::vector<float> mine;
    for (const auto& b : blocks) {
      mine.push_back(float(b.id));
      const std::vector<float> v = read(b);
      STRATA_CHECK(v.size() == size_t(perCell) * size_t(b.interior.width) * size_t(b.interior.height));
      mine.insert(mine.end(), v.begin(), v.end());
    }
    const std::vector<float> all = gatherv(mine);
    std::vector<float> out;
    if (rank != 0) return out;
    out.resize(size_t(perCell) * size_t(grid.width) * size_t(grid.height));
    for (size_t at = 0; at < all.size();) {
      const CellRect r = grid.interior(int(all[at++]));
      for (int y = 0; y < r.height; ++y) {
        const size_t d = size_t(perCell) * (size_t(r.y + y) * size_t(grid.width) + size_t(r.x));
        std::copy_n(&all[at], size_t(perCell) * size_t(r.width), &out[d]);
        at += size_t(perCell) * size_t(r.width);
      }
    }
    return out;
  }
  // The interior of a block-sized (extent) grid.
  static std::vector<float> interiorOf(const Block& b, const gis::Grid<float>& g) {
    const CellRect l = b.local(b.interior);
    std::vector<float> v;
    v.reserve(size_t(l.width) * size_t(l.height));
    for (int y = 0; y < l.height; ++y) {
      for (int x = 0; x < l.width; ++x) v.push_back(g.at(l.x + x, l.y + y));
    }
    return v;
  }
};

// -------------------------------------------------------------------------------------------------

DistributedSolver::DistributedSolver(const CellGrid& grid, const SimParams& params, std::unique_ptr<Impl> impl)
    : Solver(grid, params), impl_(std::move(impl)) {}
DistributedSolver::DistributedSolver(DistributedSolver&&) noexcept = default;
DistributedSolver& DistributedSolver::operator=(DistributedSolver&&) noexcept = default;
DistributedSolver::~DistributedSolver() = default;

Result<DistributedSolver> DistributedSolver::create(const SimInput& input, const SimParams& params,
                                                    const DistributedOptions& options, const SolverFactory& makeBlock) {
  STRATA_TRY_STATUS(validate(input, params));
  return create(regionSourceOf(input), params, options, makeBlock);
}

Result<DistributedSolver> DistributedSolver::create(const RegionSource& region, const SimParams& params,
                                                    const DistributedOptions& options, const SolverFactory& makeBlock) {
  // Checks that fail alike on every rank (the same arguments everywhere): no collective needed.
  STRATA_TRY_STATUS(checkRegionSource(region));
  STRATA_TRY_STATUS(validateParams(params));
  if (params.localStepLevels > 0) return fail(kLocalStepsOnTheCpuOnly);
  if (options.halo < 1 || options.blocksPerRank < 1 || options.blockWidth < 0 || options.blockHeight < 0 ||
      !(options.idleWeight > 0) || !(options.rebalanceAbove >= 1) || options.rebalanceEvery < 0) {
    return fail(
        "distributed: halo and blocksPerRank must be >= 1, block sizes >= 0, idleWeight > 0, rebalanceAbove >= 1, "
        "rebalanceEvery >= 0");
  }
  auto impl = std::make_unique<Impl>();
  MPI_Comm_dup(options.comm, &impl->comm);
  MPI_Comm_rank(impl->comm, &impl->rank);
  MPI_Comm_size(impl->comm, &impl->size);
  impl->options = options;
  impl->make = makeBlock;
  impl->region = region;
  impl->grid = BlockGrid::make(region.width, region.height, impl->size, options.blocksPerRank, options.blockWidth,
                               options.blockHeight, options.halo);
  int* tagUb = nullptr;
  int found = 0;
  MPI_Comm_get_attr(impl->comm, MPI_TAG_UB, &tagUb, &found);
  if (found && impl->grid.count() >= *tagUb) {
    return fail("distributed: " + std::to_string(impl->grid.count()) + " blocks, more than this MPI's message tags (" +
                std::to_string(*tagUb) + "): use larger blocks");
  }
  impl->tagMove = impl->grid.count();
  impl->pieces = detail::haloPieces(impl->grid);
  impl->order = detail::hilbertOrder(impl->grid.blocksX, impl->grid.blocksY);
  std::vector<double> cells(size_t(impl->grid.count()));
  for (int b = 0; b < impl->grid.count(); ++b) {
    const CellRect e = impl->grid.extent(b);
    cells[size_t(b)] = double(e.width) * double(e.height);
  }
  impl->owner = detail::partition(impl->order, cells, impl->size);
  impl->localIndex.assign(size_t(impl->grid.count()), -1);

  const CellGrid shape =
      CellGrid::of(region.width, region.height, int(region.materials.size()), region.rowDxM, region.dyM, region.datumM);
  DistributedSolver s(shape, params, std::move(impl));
  STRATA_TRY_STATUS(s.impl_->adoptOwners(params, {}, {}, -1.0f, {}));
  s.updateRainTotals();
  s.recordInitialTotals();
  return s;
}

std::string DistributedSolver::backendName() const {
  const auto& g = impl_->grid;
  return std::to_string(impl_->size) + " MPI ranks, " + std::to_string(g.count()) + " blocks of " +
         std::to_string(g.blockWidth) + "x" + std::to_string(g.blockHeight) + " on " +
         (impl_->blockBackend.empty() ? std::string("nothing") : impl_->blockBackend);
}

int DistributedSolver::rank() const { return impl_->rank; }
int DistributedSolver::ranks() const { return impl_->size; }
int DistributedSolver::blockCount() const { return impl_->grid.count(); }
const std::vector<int>& DistributedSolver::owners() const { return impl_->owner; }
const DistributedCounters& DistributedSolver::counters() const { return impl_->counters; }

std::vector<CellRect> DistributedSolver::localRects() const {
  std::vector<CellRect> out;
  for (const auto& b : impl_->blocks) out.push_back(b.interior);
  return out;
}

// The block of this rank whose interior holds `rect` (an internal check: the caller asks only
// for rectangles of localRects()).
const DistributedSolver::Impl::Block& DistributedSolver::Impl::holding(const CellRect& rect) const {
  for (const auto& b : blocks) {
    const CellRect in = intersect(rect, b.interior);
    if (in.width == rect.width && in.height == rect.height) return b;
  }
  STRATA_CHECK(false) << "(" << rect.x << ", " << rect.y << ") " << rect.width << "x" << rect.height
                      << " is not inside one of this rank's blocks";
  return blocks.front();
}

CellBlock DistributedSolver::readLocal(const CellRect& rect, unsigned parts) const {
  const auto& b = impl_->holding(rect);
  const CellRect l = b.local(rect);
  CellBlock out = b.solver->readBlock(l.x, l.y, l.width, l.height, parts);
  out.rect.x = rect.x;
  out.rect.y = rect.y;
  return out;
}

FloodStats DistributedSolver::readLocalFloodStats(const CellRect& rect) const {
  const auto& b = impl_->holding(rect);
  return cropFloodStats(b.solver->readFloodStats(), b.local(rect));
}

gis::Grid<float> DistributedSolver::readLocalBed(const CellRect& rect) const {
  const auto& b = impl_->holding(rect);
  return cropGrid(b.solver->readBed(), b.local(rect));
}

void DistributedSolver::forEachPart(const std::function<void(Solver&)>& f) {
  for (auto& b : impl_->blocks) f(*b.solver);
}

Status DistributedSolver::onSourceAdded(const Source& source) {
  for (auto& b : impl_->blocks) STRATA_TRY_STATUS(Impl::addSource(b, source));
  return {};
}

Status DistributedSolver::onLevelAdded(const LevelBoundary& level) {
  for (auto& b : impl_->blocks) STRATA_TRY_STATUS(Impl::addLevel(b, level));
  return {};
}

void DistributedSolver::onParamsChanged() {
  for (auto& b : impl_->blocks) {
    const auto status = b.solver->setParams(impl_->blockParams(params(), b.extent));
    STRATA_CHECK(status.ok()) << status.message();  // validated by Solver::setParams already
  }
  // Erosion or thermal weathering turned on or off changes what halos carry (haloParts); every
  // rank plans the same (setParams is collective).
  if (haloParts(params()) != impl_->halo) impl_->plan(params());
}

Solver::RainTotals DistributedSolver::rainTotals() const {
  double maxRaster = 0;
  ExactSum volume;
  const CellGrid& g = grid();
  const float uniform = params().rainMmPerHour;
  for (const auto& b : impl_->blocks) {
    size_t i = 0;
    for (int y = b.interior.y; y < b.interior.y + b.interior.height; ++y) {
      const double area = g.area(y);
      for (int x = 0; x < b.interior.width; ++x, ++i) {
        const float raster = b.rainInterior.empty() ? 0.0f : b.rainInterior[i];
        maxRaster = std::max(maxRaster, double(raster));
        volume.add(double(raster + uniform) * area);  // as rainVolumeRate: the kernels' float sum
      }
    }
  }
  RainTotals r;
  MPI_Allreduce(&maxRaster, &r.maxRasterMmH, 1, MPI_DOUBLE, MPI_MAX, impl_->comm);
  allreduceExact(&volume, 1, impl_->comm);
  r.volumeM3S = volume.value() / 3.6e6;
  return r;
}

double DistributedSolver::maxWaveSpeedMS() const {
  Timer timer(impl_->counters.reduceSeconds);
  double local = 0;
  for (auto& b : impl_->blocks) {
    if (b.speedStep != impl_->counters.steps) {
      b.speed = b.idle ? 0.0 : b.solver->maxWaveSpeedMS();
      b.speedStep = impl_->counters.steps;
    }
    local = std::max(local, b.speed);
  }
  double global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_MAX, impl_->comm);
  return global;
}

void DistributedSolver::runStep(const StepInputs& step) {
  Impl& m = *impl_;
  for (auto& b : m.blocks) m.decideIdle(b, params());
  if (m.counters.steps == 0 && m.options.balanceAtStart && m.size > 1 && m.counters.rebalances.empty()) {
    // Dealt by work before the first step, once the sources and levels (which keep their blocks
    // busy) are known.
    const auto report = rebalance();
    STRATA_CHECK(report.ok()) << report.message();
  }
  {
    Timer timer(m.counters.exchangeSeconds);
    m.exchangeStart();
  }
  for (int k : m.stepOrder) {
    auto& b = m.blocks[size_t(k)];
    {
      Timer timer(m.counters.stepSeconds);
      if (b.idle) {
        b.solver->skipStep(double(step.dtS));
        ++m.counters.idleBlockSteps;
      } else {
        b.solver->stepWithDt(double(step.dtS));
        ++m.counters.activeBlockSteps;
        m.counters.computedCells += double(b.extent.width) * double(b.extent.height);
        m.counters.interiorCells += double(b.interior.width) * double(b.interior.height);
      }
      b.skippedLast = b.idle;
    }
    Timer timer(m.counters.exchangeSeconds);
    m.send(size_t(k));
    m.progress();
  }
  {
    Timer timer(m.counters.exchangeSeconds);
    m.exchangeFinish(params());
  }
  ++m.counters.steps;
  if (m.options.rebalanceEvery > 0 && m.counters.steps % m.options.rebalanceEvery == 0) {
    const auto report = rebalance();
    STRATA_CHECK(report.ok()) << report.message();
  }
}

Result<RebalanceReport> DistributedSolver::rebalance() {
  Impl& m = *impl_;
  const double t0 = MPI_Wtime();
  const int n = m.grid.count();
  std::vector<double> local(size_t(n), 0.0), weight(size_t(n), 0.0);
  for (const auto& b : m.blocks) {
    const double cells = double(b.extent.width) * double(b.extent.height);
    local[size_t(b.id)] = b.idle ? m.options.idleWeight * cells : cells;
  }
  // One owner per block: every sum below is one value plus zeros, exact.
  MPI_Allreduce(local.data(), weight.data(), n, MPI_DOUBLE, MPI_SUM, m.comm);
  RebalanceReport report;
  report.imbalanceBefore = detail::imbalance(m.owner, weight, m.size);
  std::vector<int> next = detail::partition(m.order, weight, m.size);
  report.imbalanceAfter = detail::imbalance(next, weight, m.size);
  if (report.imbalanceBefore <= m.options.rebalanceAbove || next == m.owner ||
      report.imbalanceAfter >= report.imbalanceBefore) {
    report.imbalanceAfter = report.imbalanceBefore;
    next = m.owner;
  }
  // Moves in block order: the old owner sends the block's encoded state, the new one rebuilds the
  // block from the region's window and restores it.
  std::vector<std::string> outgoing;
  std::vector<MPI_Request> requests;
  double bytes = 0;
  for (int id = 0; id < n; ++id) {
    if (next[size_t(id)] == m.owner[size_t(id)]) continue;
    ++report.blocksMoved;
    if (m.owner[size_t(id)] != m.rank) continue;
    outgoing.push_back(encodeState(m.block(id).solver->saveState()));
  }
  requests.resize(outgoing.size());
  size_t k = 0;
  for (int id = 0; id < n; ++id) {
    if (next[size_t(id)] == m.owner[size_t(id)] || m.owner[size_t(id)] != m.rank) continue;
    STRATA_CHECK(outgoing[k].size() < size_t(INT_MAX)) << "a block's state exceeds 2 GB: use smaller blocks";
    MPI_Isend(outgoing[k].data(), int(outgoing[k].size()), MPI_BYTE, next[size_t(id)], m.tagMove, m.comm, &requests[k]);
    bytes += double(outgoing[k].size());
    ++k;
  }
  std::vector<Impl::Block> arrived;
  Status status;
  for (int id = 0; id < n; ++id) {
    if (next[size_t(id)] == m.owner[size_t(id)] || next[size_t(id)] != m.rank) continue;
    MPI_Message msg;
    MPI_Status st;
    MPI_Mprobe(m.owner[size_t(id)], m.tagMove, m.comm, &msg, &st);
    int count = 0;
    MPI_Get_count(&st, MPI_BYTE, &count);
    std::string data(size_t(count), '\0');
    MPI_Mrecv(data.data(), count, MPI_BYTE, &msg, MPI_STATUS_IGNORE);
    if (!status.ok()) continue;
    auto state = decodeState(data);
    auto b = m.build(id, params(), sources(), levels(), -1.0f);
    if (!state || !b) {
      status = fail("block " + std::to_string(id) + ": " + (state ? b.message() : state.message()));
      continue;
    }
    const auto restored = b->solver->restoreState(*state);
    if (!restored) {
      status = fail("block " + std::to_string(id) + ": " + restored.message());
      continue;
    }
    arrived.push_back(std::move(b).value());
  }
  MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
  status = Ranks::of(m.comm).agree(status);
  if (!status) return status.error();
  // Blocks that stay keep their idle state; those that arrive start active (always exact).
  m.owner = next;
  STRATA_TRY_STATUS(m.adoptOwners(params(), sources(), levels(), floodThresholdM(), std::move(arrived)));
  double elapsed = MPI_Wtime() - t0;
  MPI_Allreduce(&elapsed, &report.seconds, 1, MPI_DOUBLE, MPI_MAX, m.comm);
  MPI_Allreduce(&bytes, &report.bytesMoved, 1, MPI_DOUBLE, MPI_SUM, m.comm);
  m.counters.rebalances.push_back(report);
  return report;
}

SimStats DistributedSolver::stats() const {
  const Impl& m = *impl_;
  // stored, suspended, layers, outflow, evaporated, sediment out, level in, level out, infiltrated
  ExactSum sums[9];
  float maxDepth = 0;
  const CellGrid& g = grid();
  const int L = g.layers;
  for (const auto& b : m.blocks) {
    const CellRect l = b.local(b.interior);
    const CellBlock c = b.solver->readBlock(l.x, l.y, l.width, l.height, kBlockState | kBlockLayers | kBlockAccum);
    const size_t cells = c.cells();
    for (size_t i = 0; i < cells; ++i) {
      const double area = g.area(b.interior.y + int(i / size_t(l.width)));
      const float* st = &c.state[4 * i];
      const float* ac = &c.accum[kAccumPerCell * i];
      sums[0].add(double(st[0]) * area);
      sums[1].add(double(st[1]) * area);
      for (int k = 0; k < L; ++k) sums[2].add(double(c.layers[size_t(k) * cells + i]) * area);
      sums[3].add(double(ac[kAccumOutflow]));
      sums[4].add(double(ac[kAccumEvaporated]));
      sums[5].add(double(ac[kAccumSedimentOut]));
      sums[ac[kAccumLevel] > 0 ? 6 : 7].add(double(ac[kAccumLevel]));
      sums[8].add(double(ac[kAccumInfiltrated]));
      maxDepth = std::max(maxDepth, st[0]);
    }
  }
  allreduceExact(sums, 9, m.comm);
  float globalMax = 0;
  MPI_Allreduce(&maxDepth, &globalMax, 1, MPI_FLOAT, MPI_MAX, m.comm);
  SimStats s = counterStats();
  s.storedWaterM3 = sums[0].value();
  s.suspendedM3 = sums[1].value();
  ExactSum material = sums[1];
  material += sums[2];
  s.materialM3 = material.value();
  s.inflowM3 += sums[6].value();                    // W26: level cells that gained water on balance
  s.outflowM3 = sums[3].value() - sums[7].value();  // and those that lost (<= 0)
  s.evaporatedM3 = sums[4].value();
  s.infiltratedM3 += sums[8].value();
  s.sedimentOutflowM3 = sums[5].value();
  s.maxDepthM = globalMax;
  return s;
}

CellBlock DistributedSolver::readBlock(int x0, int y0, int width, int height, unsigned parts) const {
  CellBlock probe{.rect = {x0, y0, width, height}};
  STRATA_CHECK(blockFits(probe, grid().width, grid().height, grid().layers)) << "readBlock outside the grid";
  return impl_->gather({x0, y0, width, height}, parts, params());
}

void DistributedSolver::writeBlock(const CellBlock& block) {
  Impl& m = *impl_;
  // Rank 0's block to every rank: its rectangle, the size of each of its parts, then the parts.
  int header[4 + 6] = {block.rect.x, block.rect.y, block.rect.width, block.rect.height};  // then the six parts' sizes
  int k = 4;
  CellBlock::forEachPart(block, grid().layers,
                         [&](unsigned, const std::vector<float>& v, size_t, size_t) { header[k++] = int(v.size()); });
  if (m.rank == 0) {
    STRATA_CHECK(blockFits(block, grid().width, grid().height, grid().layers)) << "writeBlock outside the grid";
  }
  MPI_Bcast(header, 4 + 6, MPI_INT, 0, m.comm);
  CellBlock b = m.rank == 0 ? block : CellBlock{.rect = {header[0], header[1], header[2], header[3]}};
  k = 4;
  CellBlock::forEachPart(b, grid().layers, [&](unsigned, std::vector<float>& v, size_t, size_t) {
    v.resize(size_t(header[k++]));
    MPI_Bcast(v.data(), int(v.size()), MPI_FLOAT, 0, m.comm);
  });
  // Every block that sees a cell of it (interior or halo) takes it.
  for (auto& blk : m.blocks) {
    const CellRect r = b.rect.intersected(blk.extent);
    if (r.empty()) continue;
    CellBlock part{.rect = r};
    copyOverlap(b, part, grid().layers);
    part.rect.x -= blk.extent.x;
    part.rect.y -= blk.extent.y;
    blk.solver->writeBlock(part);
  }
  m.invalidate();
}

gis::Grid<float> DistributedSolver::readWaterDepth() const {
  if (rank() == 0) return Solver::readWaterDepth();
  (void)readBlock(0, 0, grid().width, grid().height, kBlockState);
  return {};
}

gis::Grid<float> DistributedSolver::readSuspended() const {
  if (rank() == 0) return Solver::readSuspended();
  (void)readBlock(0, 0, grid().width, grid().height, kBlockState);
  return {};
}

VelocityField DistributedSolver::readVelocity() const {
  if (rank() == 0) return Solver::readVelocity();
  (void)readBlock(0, 0, grid().width, grid().height, kBlockState);
  return {};
}

std::vector<gis::Grid<float>> DistributedSolver::readLayers() const {
  if (rank() == 0) return Solver::readLayers();
  (void)readBlock(0, 0, grid().width, grid().height, kBlockLayers);
  return {};
}

gis::Grid<float> DistributedSolver::readBed() const {
  auto cells = impl_->gatherCells(1, [](const Impl::Block& b) { return Impl::interiorOf(b, b.solver->readBed()); });
  if (rank() != 0) return {};
  gis::Grid<float> g(grid().width, grid().height);
  g.data = std::move(cells);
  return g;
}

FloodStats DistributedSolver::readFloodStats() const {
  auto cells = impl_->gatherCells(4, [](const Impl::Block& b) {
    const FloodStats f = b.solver->readFloodStats();
    const std::vector<float> parts[4] = {Impl::interiorOf(b, f.maxDepthM), Impl::interiorOf(b, f.maxSpeedMS),
                                         Impl::interiorOf(b, f.arrivalS), Impl::interiorOf(b, f.wetDurationS)};
    std::vector<float> v(4 * parts[0].size());
    for (size_t i = 0; i < parts[0].size(); ++i) {
      for (int k = 0; k < 4; ++k) v[4 * i + size_t(k)] = parts[k][i];
    }
    return v;
  });
  if (rank() != 0) return {};
  return floodStatsFromCells(cells, grid().width, grid().height);
}

std::vector<float> DistributedSolver::readFaceMassFlux() const {
  STRATA_CHECK(params().waterModel == WaterModel::kFiniteVolume) << "face fluxes exist in flood mode only";
  const Impl& m = *impl_;
  const int w = grid().width, h = grid().height;
  // A block owns the west and north faces of its interior cells, and the region's east and south
  // edge faces where it reaches them (as TiledSolver). A block that skipped the last step moved
  // nothing: its faces are 0, as the step would have computed them.
  auto forFaces = [w, h](const CellRect& r, auto&& fx, auto&& fy) {
    const int x1 = r.x + r.width, y1 = r.y + r.height;
    for (int y = r.y; y < y1; ++y) {
      for (int x = r.x; x < (x1 == w ? w + 1 : x1); ++x) fx(x, y);
    }
    for (int y = r.y; y < (y1 == h ? h + 1 : y1); ++y) {
      for (int x = r.x; x < x1; ++x) fy(x, y);
    }
  };
  std::vector<float> mine;
  for (const auto& b : m.blocks) {
    mine.push_back(float(b.id));
    const std::vector<float> f = b.skippedLast ? std::vector<float>() : b.solver->readFaceMassFlux();
    const int tw = b.extent.width, th = b.extent.height;
    const size_t tOffY = size_t(tw + 1) * size_t(th);
    forFaces(
        b.interior,
        [&](int x, int y) {
          mine.push_back(f.empty() ? 0.0f : f[size_t(y - b.extent.y) * size_t(tw + 1) + size_t(x - b.extent.x)]);
        },
        [&](int x, int y) {
          mine.push_back(f.empty() ? 0.0f : f[tOffY + size_t(y - b.extent.y) * size_t(tw) + size_t(x - b.extent.x)]);
        });
  }
  const std::vector<float> all = m.gatherv(mine);
  std::vector<float> out;
  if (m.rank != 0) return out;
  out.resize(size_t(w + 1) * size_t(h) + size_t(w) * size_t(h + 1));
  const size_t offY = size_t(w + 1) * size_t(h);
  for (size_t at = 0; at < all.size();) {
    const CellRect r = m.grid.interior(int(all[at++]));
    forFaces(
        r, [&](int x, int y) { out[size_t(y) * size_t(w + 1) + size_t(x)] = all[at++]; },
        [&](int x, int y) { out[offY + size_t(y) * size_t(w) + size_t(x)] = all[at++]; });
  }
  return out;
}

void DistributedSolver::resetFloodStats() {
  for (auto& b : impl_->blocks) b.solver->enableFloodStats(floodThresholdM());
}

void DistributedSolver::saveCells(SolverState& out) const {
  const Impl& m = *impl_;
  const auto& g = m.grid;
  out.numbers = {double(g.width),       double(g.height), double(g.blockWidth),
                 double(g.blockHeight), double(g.halo),   double(m.size)};
  out.tags.assign(m.owner.begin(), m.owner.end());
  for (const auto& b : m.blocks) out.parts.push_back(b.solver->saveState());
}

Status DistributedSolver::restoreCells(const SolverState& in) {
  Impl& m = *impl_;
  const auto& g = m.grid;
  const std::vector<double> shape = {double(g.width),       double(g.height), double(g.blockWidth),
                                     double(g.blockHeight), double(g.halo),   double(m.size)};
  Status status;
  std::vector<int> owner(in.tags.begin(), in.tags.end());
  size_t mineCount = 0;
  bool ownersOk = owner.size() == size_t(g.count());
  for (int o : owner) {
    ownersOk = ownersOk && o >= 0 && o < m.size;
    mineCount += o == m.rank ? 1 : 0;
  }
  if (in.numbers != shape) {
    status =
        fail("distributed: the saved state is of another region, block grid or number of ranks (" +
             (in.numbers.size() == 6 ? std::to_string(int(in.numbers[5])) + " ranks" : std::string("not distributed")) +
             ", this run has " + std::to_string(m.size) + ")");
  } else if (!ownersOk || in.parts.size() != mineCount) {
    status = fail("distributed: the saved state's blocks do not match its block grid (rank " + std::to_string(m.rank) +
                  " has " + std::to_string(in.parts.size()) + " parts)");
  }
  STRATA_TRY_STATUS(Ranks::of(m.comm).agree(status));
  if (owner != m.owner) {
    m.owner = owner;
    STRATA_TRY_STATUS(m.adoptOwners(params(), sources(), levels(), floodThresholdM(), {}));
  }
  size_t k = 0;
  for (auto& b : m.blocks) {
    const auto restored = b.solver->restoreState(in.parts[k++]);
    if (!restored) {
      status = fail("block " + std::to_string(b.id) + ": " + restored.message());
      break;
    }
  }
  m.invalidate();
  return Ranks::of(m.comm).agree(status);
}

// -------------------------------------------------------------------------------------------------

int localRank(MPI_Comm comm) {
  MPI_Comm node;
  MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
  int r = 0;
  MPI_Comm_rank(node, &r);
  MPI_Comm_free(&node);
  return r;
}

std::string rankEglDevice(MPI_Comm comm) { return "gpu:" + std::to_string(localRank(comm)); }

}  // namespace strata::sim
