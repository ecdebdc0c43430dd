#version 450
// Overlay (text boxes, the scale bar): one flat colour per draw.
uniform vec4 uColour;
layout(location = 0) out vec4 outColour;

void main() { outColour = uColour; }
