#include "probes.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>

namespace strata::scenario::detail {

Probes::Probes(const ScenarioDomain& d, const sim::CellGrid& grid, double intervalS)
    : gauges_(d.gauges),
      sections_(d.sections),
      intervalS_(intervalS),
      datumM_(grid.datumM),
      dryDepthM_(d.params.dryDepthM) {
  // Face lengths as the solver's mass update takes them (cpu_solver.cpp, faceWidthY): an x face
  // is dy long, a y face the mean of its two rows' dx, both in float.
  for (const auto& s : sections_) {
    std::vector<double> lengths;
    for (const auto& f : s.faces) {
      const float dy = float(grid.dyM);
      const float dx = f.xFace ? dy : 0.5f * (float(grid.rowDxM[size_t(f.y) - 1]) + float(grid.rowDxM[size_t(f.y)]));
      lengths.push_back(double(dx));
    }
    faceLengthsM_.push_back(std::move(lengths));
  }
  // Every section's faces in one list, numbered as Solver::readFaceMassFlux numbers them.
  const size_t w = size_t(grid.width), offY = (w + 1) * size_t(grid.height);
  for (const auto& s : sections_) {
    for (const auto& f : s.faces) {
      faceIndices_.push_back(f.xFace ? size_t(f.y) * (w + 1) + size_t(f.x) : offY + size_t(f.y) * w + size_t(f.x));
    }
  }
  gaugePeak_.assign(gauges_.size(), 0.0);
  gaugePeakS_.assign(gauges_.size(), -1.0);
  for (auto* v : {&forward_, &back_, &peakQ_, &lastQ_}) v->assign(sections_.size(), 0.0);
  peakQS_.assign(sections_.size(), -1.0);
}

Probes::GaugeNow Probes::readGauge(const sim::Solver& solver, size_t k) const {
  const auto& g = gauges_[k];
  const auto b = solver.readBlock(g.x, g.y, 1, 1, sim::kBlockState);
  const auto bed = solver.readLocalBed({g.x, g.y, 1, 1});
  GaugeNow n;
  n.depthM = std::max(0.0f, b.state[0]);
  n.levelM = datumM_ + double(bed.data[0]) + n.depthM;
  if (b.state[0] > dryDepthM_) {
    const double u = b.state[2] / b.state[0], v = b.state[3] / b.state[0];  // east, south
    n.speedMS = std::hypot(u, v);
    // The bearing the water flows toward: 0 north, 90 east.
    if (n.speedMS > 0) n.towardDeg = std::fmod(std::atan2(u, -v) * 180.0 / std::numbers::pi + 360.0, 360.0);
  }
  return n;
}

double Probes::meanLevel(const sim::Solver& solver, size_t k) const {
  double sum = 0;
  int wet = 0;
  for (auto [x, y] : sections_[k].cells) {
    const auto b = solver.readBlock(x, y, 1, 1, sim::kBlockState);
    if (!(b.state[0] > dryDepthM_)) continue;
    sum += datumM_ + double(solver.readLocalBed({x, y, 1, 1}).data[0]) + b.state[0];
    ++wet;
  }
  return wet > 0 ? sum / wet : std::nan("");
}

void Probes::afterStep(const sim::Solver& solver, double dtS) {
  const double t = solver.timeS();
  for (size_t k = 0; k < gauges_.size(); ++k) {
    const double depth = std::max(0.0f, solver.readBlock(gauges_[k].x, gauges_[k].y, 1, 1, sim::kBlockState).state[0]);
    if (depth > gaugePeak_[k]) gaugePeak_[k] = depth, gaugePeakS_[k] = t;
  }
  if (sections_.empty()) return;
  const auto flux = solver.readFaceMassFluxAt(faceIndices_);
  size_t at = 0;
  for (size_t k = 0; k < sections_.size(); ++k) {
    double q = 0;
    const auto& faces = sections_[k].faces;
    for (size_t i = 0; i < faces.size(); ++i) q += double(faces[i].sign) * double(flux[at++]) * faceLengthsM_[k][i];
    lastQ_[k] = q;
    (q >= 0 ? forward_[k] : back_[k]) += std::abs(q) * dtS;
    if (std::abs(q) > std::abs(peakQ_[k])) peakQ_[k] = q, peakQS_[k] = t;
  }
}

void Probes::row(const sim::Solver& solver) {
  rows_.push_back(solver.timeS());
  for (size_t k = 0; k < gauges_.size(); ++k) {
    const auto n = readGauge(solver, k);
    rows_.insert(rows_.end(), {n.depthM, n.levelM, n.speedMS, n.towardDeg});
  }
  for (size_t k = 0; k < sections_.size(); ++k) {
    rows_.insert(rows_.end(), {lastQ_[k], forward_[k] - back_[k], meanLevel(solver, k)});
  }
  while (nextRowS_ <= solver.timeS() + 1e-9 * std::max(1.0, std::abs(nextRowS_))) nextRowS_ += intervalS_;
}

std::vector<double> Probes::save() const {
  std::vector<double> out{nextRowS_};
  for (const auto* v : {&gaugePeak_, &gaugePeakS_, &forward_, &back_, &peakQ_, &peakQS_, &lastQ_})
    out.insert(out.end(), v->begin(), v->end());
  out.insert(out.end(), rows_.begin(), rows_.end());
  return out;
}

Status Probes::restore(const std::vector<double>& saved) {
  const size_t head = 1 + 2 * gauges_.size() + 5 * sections_.size();
  const size_t perRow = 1 + 4 * gauges_.size() + 3 * sections_.size();
  if (saved.size() < head || (saved.size() - head) % perRow != 0) {
    return fail("the checkpoint's gauges and sections do not match the scenario's");
  }
  size_t at = 0;
  nextRowS_ = saved[at++];
  for (auto* v : {&gaugePeak_, &gaugePeakS_, &forward_, &back_, &peakQ_, &peakQS_, &lastQ_}) {
    for (auto& x : *v) x = saved[at++];
  }
  rows_.assign(saved.begin() + std::ptrdiff_t(at), saved.end());
  return {};
}

namespace {

// A CSV field: the name quoted (doubled quotes inside), so that any name keeps its column.
std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string number(double v, const char* format) {
  if (!std::isfinite(v)) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

}  // namespace

// Long format (one line per probe and time): a name is data, not a column header. Each row holds
// the probes' values from `offset` on, `formats.size()` per probe.
std::string Probes::longCsv(const char* header, const std::vector<std::string>& names, size_t offset,
                            const std::vector<const char*>& formats) const {
  if (names.empty()) return {};
  std::string out = header;
  const size_t perRow = 1 + 4 * gauges_.size() + 3 * sections_.size();
  for (size_t r = 0; r + perRow <= rows_.size(); r += perRow) {
    for (size_t k = 0; k < names.size(); ++k) {
      out += number(rows_[r], "%.3f") + "," + quoted(names[k]);
      for (size_t j = 0; j < formats.size(); ++j) {
        out += "," + number(rows_[r + offset + formats.size() * k + j], formats[j]);
      }
      out += "\n";
    }
  }
  return out;
}

std::string Probes::gaugesCsv() const {
  std::vector<std::string> names;
  for (const auto& g : gauges_) names.push_back(g.name);
  return longCsv("time_s,gauge,depth_m,level_m,speed_m_s,toward_deg\n", names, 1, {"%.4f", "%.4f", "%.4f", "%.1f"});
}

std::string Probes::sectionsCsv() const {
  std::vector<std::string> names;
  for (const auto& s : sections_) names.push_back(s.name);
  return longCsv("time_s,section,discharge_m3_s,volume_m3,mean_level_m\n", names, 1 + 4 * gauges_.size(),
                 {"%.6g", "%.9g", "%.4f"});
}

std::vector<ProbeSummary> Probes::gaugeSummaries() const {
  std::vector<ProbeSummary> out;
  for (size_t k = 0; k < gauges_.size(); ++k) {
    ProbeSummary p;
    p.name = gauges_[k].name;
    p.x = gauges_[k].x, p.y = gauges_[k].y;
    p.peak = gaugePeak_[k], p.peakTimeS = gaugePeakS_[k];
    out.push_back(p);
  }
  return out;
}

std::vector<ProbeSummary> Probes::sectionSummaries() const {
  std::vector<ProbeSummary> out;
  for (size_t k = 0; k < sections_.size(); ++k) {
    ProbeSummary p;
    p.name = sections_[k].name;
    p.faces = int(sections_[k].faces.size());
    p.peak = peakQ_[k], p.peakTimeS = peakQS_[k];
    p.volumeM3 = forward_[k] - back_[k], p.forwardM3 = forward_[k], p.backM3 = back_[k];
    out.push_back(p);
  }
  return out;
}

}  // namespace strata::scenario::detail
