#version 450
// Copies every field of a GridParams, as the GPU reads it, into a float array: the test
// writes distinct values from C++ and expects them back in declaration order.
#include "grid.glsl"
layout(local_size_x = 1) in;

layout(std430, binding = 0) readonly buffer Params { GridParams grid; };
layout(std430, binding = 1) writeonly buffer Fields { float fields[]; };

void main() {
  fields[0] = float(grid.size.x);
  fields[1] = float(grid.size.y);
  fields[2] = grid.cellSizeM.x;
  fields[3] = grid.cellSizeM.y;
  fields[4] = grid.datumM;
  fields[5] = grid.noData;
  fields[6] = float(grid.flags);
  fields[7] = float(grid.pad0);
  fields[8] = grid.sun.x;
  fields[9] = grid.sun.y;
  fields[10] = grid.sun.z;
  fields[11] = grid.sun.w;
}
