#version 450
// A rectangle of cells of a per-cell buffer to or from a packed buffer, so the host moves a block
// that is not whole rows (a halo strip, a tile) in one transfer instead of one per row
// (GlSolver::readBlock / writeBlock). The grid buffer holds planes of gridCells cells, `perCell`
// floats each, of which this moves `planes` from `firstPlane` on; the packed one holds the
// rectangle plane by plane, row by row, the same floats per cell (CellBlock's layout).
// scatter = 0: grid -> packed; 1: packed -> grid.
layout(local_size_x = 64, local_size_y = 4) in;
layout(std430, binding = SLOT_COPY_GRID) buffer Grid { float grid[]; };
layout(std430, binding = SLOT_COPY_PACKED) buffer Rect { float rect[]; };
uniform uint gridWidth;
uniform uint gridCells;
uniform uint x0;
uniform uint y0;
uniform uint width;   // cells
uniform uint height;  // cells
uniform uint perCell;
uniform uint planes;
uniform uint firstPlane;
uniform uint scatter;
void main() {
  const uint fx = gl_GlobalInvocationID.x, row = gl_GlobalInvocationID.y;  // float in the row, row of all planes
  if (fx >= width * perCell || row >= height * planes) return;
  const uint plane = row / height, y = row % height;
  const uint g = ((firstPlane + plane) * gridCells + (y0 + y) * gridWidth + x0) * perCell + fx;
  const uint p = row * width * perCell + fx;
  if (scatter == 0u) {
    rect[p] = grid[g];
  } else {
    grid[g] = rect[p];
  }
}
