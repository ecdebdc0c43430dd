// Material layers: thickness of layer l in cell i at layers[l * n + i] (bottom to top); the
// bed (datum-relative) is base + the sum of the layers, recomputed by whoever changes them.
layout(std430, binding = SLOT_MATERIALS) readonly buffer Materials { SimMaterial materials[]; };
layout(std430, binding = SLOT_BASE) readonly buffer Base { float baseM[]; };
layout(std430, binding = SLOT_LAYERS) buffer Layers { float layers[]; };

int cellCount() { return P.width * P.height; }
// Topmost layer with material, or -1.
int topLayer(int i) {
  for (int l = P.layerCount - 1; l >= 0; --l) {
    if (layers[l * cellCount() + i] > 0.0) return l;
  }
  return -1;
}
// E9 (docs/sim-erosion.md): what a store of `from` m really loses when `amount` (<= from) is
// taken off it: from - fl(from - amount), exact (Sterbenz). `precise` keeps the compiler from
// folding it back to `amount`.
float exactTake(float from, float amount) {
  precise float left = from - amount;
  precise float lost = from - left;
  return lost;
}
// E9, receiving side: what a store of `to` m really gains from `amount` when it is the larger of
// the two; 0 when that exceeds `limit`, what the giver holds.
float exactGive(float to, float amount, float limit) {
  precise float sum = to + amount;
  precise float gained = to >= amount ? sum - to : amount;
  return gained <= limit ? gained : 0.0;
}
float bedOf(int i) {
  float b = baseM[i];
  for (int l = 0; l < P.layerCount; ++l) b += layers[l * cellCount() + i];
  return b;
}
