// Material layers: thickness of layer l in cell i at layers[l * n + i] (bottom to top); the
// bed (datum-relative) is base + the sum of the layers, recomputed by whoever changes them.
layout(std430, binding = 1) readonly buffer Materials { SimMaterial materials[]; };
layout(std430, binding = 3) readonly buffer Base { float baseM[]; };
layout(std430, binding = 5) buffer Layers { float layers[]; };

int cellCount() { return P.width * P.height; }
// Topmost layer with material, or -1.
int topLayer(int i) {
  for (int l = P.layerCount - 1; l >= 0; --l) {
    if (layers[l * cellCount() + i] > 0.0) return l;
  }
  return -1;
}
float bedOf(int i) {
  float b = baseM[i];
  for (int l = 0; l < P.layerCount; ++l) b += layers[l * cellCount() + i];
  return b;
}
