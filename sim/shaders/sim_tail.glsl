// W36: the tail of a device step (W35) fused into its water update (the local-inertial update, the
// finite-volume corrector), when nothing after the update changes the state (no levels, erosion
// or thermal weathering): the flood statistics of the new state (sim_stats.glsl) and its wave
// speed for the next step's clock (W10, waveSpeedOf), reduced in the work group and added with
// one atomicMax per group to maxSpeedBits, which step_clock.comp zeroes once it has read it.
// Saves wave_speed.comp's and flood_stats.comp's passes over the grid and their dispatches.
#define CLOCK_QUALIFIER readonly
#include "sim_clock.glsl"
#include "sim_stats.glsl"
layout(std430, binding = SLOT_MAX_SPEED) buffer MaxSpeed { uint maxSpeedBits; };
uniform uint tailSpeed;  // 1: the new state's wave speed into maxSpeedBits
uniform uint tailStats;  // 1: the flood statistics of the new state
shared uint sTailMax;

// Called once by every invocation (uniform control flow): `wrote` when the invocation's cell got
// its new state `s`.
void stepTail(ivec2 p, bool wrote, vec4 s) {
  if (tailStats != 0u && wrote) floodStatsAt(uint(cellOf(p)), s, float(C.timeS));
  if (tailSpeed == 0u) return;
  if (gl_LocalInvocationIndex == 0u) sTailMax = 0u;
  barrier();
  if (wrote) atomicMax(sTailMax, floatBitsToUint(waveSpeedOf(s)));
  barrier();
  if (gl_LocalInvocationIndex == 0u && sTailMax != 0u) atomicMax(maxSpeedBits, sTailMax);
}
