#version 330 core
// Drawn over O's active blocks: the bits by which a pixel wakes the pure colours' fit around
// it, over 255 (pure_colour_blocks.glsl); flag_wakes.comp then flags the blocks near them.
#include "working.glsl"
#include "pure_colour_blocks.glsl"

out vec4 wakes;

void main() {
    wakes = vec4(float(pure_colour_wakes(ivec2(gl_FragCoord.xy), textureSize(original_work, 0))) / 255.0);
}
