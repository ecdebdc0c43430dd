#version 450
// The bed of a rectangle of cells from its base and layers, after writeBlock replaced layers:
// base + layer 0 + layer 1 + ..., in that order (CpuSolver::recomputeBed), so both backends
// agree to the bit.
layout(local_size_x = 16, local_size_y = 16) in;
layout(std430, binding = SLOT_BASE) readonly buffer Base { float base[]; };
layout(std430, binding = SLOT_BED) buffer Bed { float bed[]; };
layout(std430, binding = SLOT_LAYERS) readonly buffer Layers { float layers[]; };
uniform uint gridWidth;
uniform uint gridCells;
uniform uint layerCount;
uniform uint x0;
uniform uint y0;
uniform uint width;
uniform uint height;
void main() {
  if (gl_GlobalInvocationID.x >= width || gl_GlobalInvocationID.y >= height) return;
  const uint i = (y0 + gl_GlobalInvocationID.y) * gridWidth + x0 + gl_GlobalInvocationID.x;
  precise float b = base[i];
  for (uint l = 0u; l < layerCount; ++l) b += layers[l * gridCells + i];
  bed[i] = b;
}
