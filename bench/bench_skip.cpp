// What "work follows the water" saves on a real scenario: its domain (the region, inflows,
// levels, rain, flood statistics) on the CPU backend twice side by side, every cell every step
// and skipping the quiet blocks, over the scenario's duration (or the one given). One JSON line
// per run: wall seconds, steps, cell updates as a fraction of cells x steps, and for the second
// run whether its final state, budgets and flood statistics are the first run's bits.
//   build/bench/strata_bench_skip SCENARIO.toml [duration_s [threads]]
// Figures go to docs/benchmarks.md.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include <strata/scenario/domain.hpp>
#include <strata/scenario/scenario.hpp>
#include <strata/sim/cpu_solver.hpp>

namespace {
using namespace strata;

struct Outcome {
  sim::SolverState state;
  double wallS = 0, fraction = 0;
  long long steps = 0;
  int threads = 0;
};

Result<Outcome> runOnce(const scenario::Scenario& s, const scenario::ScenarioDomain& d, double durationS,
                        sim::CpuOptions options) {
  STRATA_TRY(auto solver, sim::CpuSolver::create(d.input, d.params, options));
  for (const auto& src : d.sources) STRATA_TRY_STATUS(solver.addSource(src));
  for (const auto& level : d.levels) STRATA_TRY_STATUS(solver.addLevel(level));
  solver.enableFloodStats(float(s.outputs.wetThresholdM));
  const auto t0 = std::chrono::steady_clock::now();
  // Rain as the scenario runner gives it: uniform while it falls, switched at its times.
  double t = 0;
  for (double edge : {d.rainStartS, d.rainEndS, durationS}) {
    if (edge <= t) continue;
    auto p = solver.params();
    p.rainMmPerHour = float(t >= d.rainStartS && t < d.rainEndS ? d.rainMmPerHour : 0.0);
    STRATA_TRY_STATUS(solver.setParams(p));
    const double end = std::min(edge, durationS);
    solver.advance(end - t);
    t = end;
    if (t >= durationS) break;
  }
  Outcome o;
  o.threads = solver.threads();
  o.wallS = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  o.steps = solver.counterStats().steps;
  o.fraction = double(solver.cellUpdates()) / (double(solver.grid().cells()) * double(o.steps));
  o.state = solver.saveState();
  return o;
}

bool sameBits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s SCENARIO.toml [duration_s [threads]]\n", argv[0]);
    return 2;
  }
  auto s = scenario::loadScenario(argv[1]);
  if (!s) {
    std::fprintf(stderr, "%s\n", s.message().c_str());
    return 1;
  }
  auto d = scenario::buildDomain(*s);
  if (!d) {
    std::fprintf(stderr, "%s\n", d.message().c_str());
    return 1;
  }
  const double durationS = argc > 2 ? std::atof(argv[2]) : s->durationS;
  const int threads = argc > 3 ? std::atoi(argv[3]) : 0;
  Outcome first;
  for (bool skip : {false, true}) {
    auto o = runOnce(*s, *d, durationS, sim::CpuOptions{threads, skip});
    if (!o) {
      std::fprintf(stderr, "%s\n", o.message().c_str());
      return 1;
    }
    const bool same =
        !skip || (sameBits(o->state.state, first.state.state) && sameBits(o->state.accum, first.state.accum) &&
                  sameBits(o->state.flood, first.state.flood));
    std::printf(
        "{\"scenario\": \"%s\", \"cells\": %d, \"duration_s\": %.0f, \"skip\": %s, \"threads\": %d, \"wall_s\": %.3f, "
        "\"steps\": %lld, \"ms_per_step\": %.3f, \"cells_updated_fraction\": %.4f, \"same_bits_as_every_cell\": %s}\n",
        s->name.c_str(), d->input.baseM.width * d->input.baseM.height, durationS, skip ? "true" : "false", o->threads,
        o->wallS, o->steps, 1e3 * o->wallS / double(o->steps), o->fraction, same ? "true" : "false");
    std::fflush(stdout);
    if (!skip) first = std::move(o).value();
  }
  return 0;
}
