#pragma once
// How the CPU passes walk a row: the cells of an edge column or row through the general code
// (neighbours may be missing, scalar), the others through the interior code (all neighbours
// there, no checks), as a loop the compiler vectorises.

#include <type_traits>

namespace strata::sim::cpu {

using Edge = std::true_type;
using Interior = std::false_type;

/// Calls cell(Edge{}, x) for x in [x0, x1) in column 0, column w - 1 or anywhere when `edgeRow`,
/// and cell(Interior{}, x) for the others. `cell` is taken by value, so what it captures by value
/// is local to the loop (a capture by reference would be reloaded from memory each iteration,
/// which the compiler cannot vectorise).
template <class Cell>
inline void forRowCells(int x0, int x1, int w, bool edgeRow, Cell cell) {
  if (edgeRow) {
    for (int x = x0; x < x1; ++x) cell(Edge{}, x);
    return;
  }
  int xa = x0, xb = x1;
  if (xa == 0 && xb > 0) cell(Edge{}, xa++);
  const bool last = xb == w && xb > xa;
  if (last) --xb;
#pragma omp simd
  for (int x = xa; x < xb; ++x) cell(Interior{}, x);
  if (last) cell(Edge{}, w - 1);
}

/// Calls edge(x) for the cells of [x0, x1) in column 0, column w - 1 or anywhere when `edgeRow`,
/// and interior(xa, xb) once for the others (a contiguous range, possibly empty: not called).
template <class EdgeCell, class InteriorCells>
inline void forEdgesAndInterior(int x0, int x1, int w, bool edgeRow, EdgeCell&& edge, InteriorCells&& interior) {
  if (edgeRow) {
    for (int x = x0; x < x1; ++x) edge(x);
    return;
  }
  int xa = x0, xb = x1;
  if (xa == 0 && xb > 0) edge(xa++);
  const bool last = xb == w && xb > xa;
  if (last) --xb;
  if (xb > xa) interior(xa, xb);
  if (last) edge(w - 1);
}

}  // namespace strata::sim::cpu
