// W12b: the finite-volume scheme pours half of each point source's step into its cell before its
// faces and keeps the other half in `pour` for its corrector to add to the step's new state
// (Strang splitting, docs/sim-water.md); the pipes and the local-inertial scheme (which pours after
// its faces, W38) pour it all at once. Each cell is listed once, so `pour` needs no atomics; the
// corrector sets what it added back to 0.
layout(std430, binding = SLOT_POUR) buffer Pour { float pour[]; };
bool splitsPour() { return P.waterModel == 1 && P.floodScheme == 0; }
#ifdef POUR_INTO_STATE
// W12 for one entry (point_sources.comp, step_clock.comp); `state` is the step's state.
void pourPointSource(SourceEntry e) {
  float d = pointSourceDepth(e);
  if (splitsPour()) {
    d *= 0.5;
    pour[e.cell] = d;
  }
  state[e.cell].x = addDepth(state[e.cell].x, int(e.cell), d);
}
#endif
