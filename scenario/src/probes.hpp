#pragma once
// Gauges and cross-sections ([[outputs.gauge]], [[outputs.section]], docs/scenario.md): what a
// run records at points and across lines. A section's discharge is summed from the face fluxes
// the solver applied (Solver::readFaceMassFluxAt) after every step, so the volume through it is the
// water that crossed it, exactly as the balance counts it; a gauge's peak depth is taken after
// every step too (as the max_depth map is). Rows are written every [outputs] probe_interval.

#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/scenario/domain.hpp>
#include <strata/scenario/run.hpp>
#include <strata/sim/solver.hpp>

namespace strata::scenario::detail {

using scenario::ProbeSummary;

class Probes {
 public:
  Probes(const ScenarioDomain& d, const sim::CellGrid& grid, double intervalS);
  bool empty() const { return gauges_.empty() && sections_.empty(); }
  /// The next time a row is due (s).
  double nextRowS() const { return nextRowS_; }
  /// The sections' faces, numbered as Solver::readFaceMassFlux numbers them.
  const std::vector<size_t>& faceIndices() const { return faceIndices_; }
  /// After a step of `dtS` (flood mode; the run's clock, not the spin-up's).
  void afterStep(const sim::Solver& solver, double dtS);
  /// Writes the row of the solver's time (once it has reached nextRowS()).
  void row(const sim::Solver& solver);
  /// The state to continue from (a checkpoint), and back.
  std::vector<double> save() const;
  Status restore(const std::vector<double>& saved);
  /// gauges.csv and sections.csv (empty strings when there are none).
  std::string gaugesCsv() const;
  std::string sectionsCsv() const;
  std::vector<ProbeSummary> gaugeSummaries() const;
  std::vector<ProbeSummary> sectionSummaries() const;

 private:
  struct GaugeNow {
    double depthM = 0, levelM = 0, speedMS = 0, towardDeg = 0;
  };
  GaugeNow readGauge(const sim::Solver& solver, size_t k) const;
  double meanLevel(const sim::Solver& solver, size_t k) const;
  std::string longCsv(const char* header, const std::vector<std::string>& names, size_t offset,
                      const std::vector<const char*>& formats) const;

  std::vector<ScenarioDomain::GaugeCell> gauges_;
  std::vector<ScenarioDomain::SectionFaces> sections_;
  std::vector<std::vector<double>> faceLengthsM_;  // per section, per face
  std::vector<size_t> faceIndices_;                // all sections' faces, in order
  double intervalS_ = 60, nextRowS_ = 0, datumM_ = 0;
  float dryDepthM_ = 1e-6f;
  // Sums: per gauge peak depth and its time; per section forward, back, peak discharge and its
  // time, and the discharge of the last step.
  std::vector<double> gaugePeak_, gaugePeakS_, forward_, back_, peakQ_, peakQS_, lastQ_;
  std::vector<double> rows_;  // flat: time, then 4 per gauge, then 3 per section
};

}  // namespace strata::scenario::detail
