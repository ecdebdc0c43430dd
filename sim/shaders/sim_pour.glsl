// W12b: the finite-volume scheme pours half of each point source's step into its cell before its
// faces and keeps the other half in the accumulators' buffer, in the plane after them
// (ACCUM_POUR), for its corrector to add to the step's new state (Strang splitting,
// docs/sim-water.md); the pipes and the local-inertial scheme (which pours after its faces, W38)
// pour it all at once. Each cell is listed once, so the plane needs no atomics; the corrector sets
// what it added back to 0. A plane of a buffer these kernels bind already, not a block of its own:
// a kernel may declare 16 storage blocks (GL_MAX_COMPUTE_SHADER_STORAGE_BLOCKS on llvmpipe and
// NVIDIA; a 17th fails the link) and fv_update.comp declares 15. Needs sim_accum.glsl.
bool splitsPour() { return P.waterModel == 1 && P.floodScheme == 0; }  // flood mode, finite volumes
uint pourAt(int cell) { return accumAt(cell, ACCUM_POUR); }
#ifdef POUR_INTO_STATE
// W12 for one entry (point_sources.comp, step_clock.comp); `state` is the step's state.
void pourPointSource(SourceEntry e) {
  float d = pointSourceDepth(e);
  if (splitsPour()) {
    d *= 0.5;
    accum[pourAt(int(e.cell))] = d;
  }
  state[e.cell].x = addDepth(state[e.cell].x, int(e.cell), d);
}
#endif
