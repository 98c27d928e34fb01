#version 330 core
// O and F into the working space once per image pair, so that no later pass decodes sRGB
// (the fit alone would otherwise decode 18 texels per pixel on every parameter change).
// Twin: to_working_space in aarecovery/spec/working_space.py.
#include "colour.glsl"

uniform sampler2D original_image;
uniform sampler2D filtered_image;

layout(location = 0) out vec4 original_work;
layout(location = 1) out vec4 filtered_work;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    original_work = to_working(texelFetch(original_image, p, 0), INPUT_CONVERT);
    filtered_work = to_working(texelFetch(filtered_image, p, 0), INPUT_CONVERT);
}
