// W25's limits as the updates read them (fv_update.comp, inertial_update.comp): fv_limit.comp's
// share K of its outgoing flux each cell can give.
layout(std430, binding = SLOT_FV_LIMIT) readonly buffer Limit { float limit_[]; };

// The share of a face's mass flux its upwind cell can give (l: left / top cell, r: right /
// bottom); only outflow crosses an edge, so an upwind cell outside the grid never limits.
float limitOfFace(float massFlux, ivec2 l, ivec2 r) {
  const ivec2 up = massFlux > 0.0 ? l : r;
  return insideGrid(up) ? limit_[cellOf(up)] : 1.0;
}
