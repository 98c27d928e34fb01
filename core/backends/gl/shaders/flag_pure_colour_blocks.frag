#version 330 core
// Drawn over O's active blocks: 1 where a pixel wakes the pure colours' fit around it
// (pure_colour_blocks.glsl); flag_wakes.comp then flags the blocks near such pixels.
#include "working.glsl"
#include "pure_colour_blocks.glsl"

out vec4 wakes;

void main() {
    wakes = vec4(float(wakes_pure_colours(ivec2(gl_FragCoord.xy), textureSize(original_work, 0))));
}
