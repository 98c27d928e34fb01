#version 430
// flag_pure_colour_blocks.frag on the compute path, over O's active blocks.
#include "compute.glsl"
#include "working.glsl"
#include "pure_colour_blocks.glsl"

layout(r8, binding = 0) uniform writeonly image2D wakes;

void main() {
    ivec2 p = block_origin() + ivec2(gl_LocalInvocationID.xy);
    if (!inside_image(p)) return;
    imageStore(wakes, p, vec4(float(pure_colour_wakes(p, image_size)) / 255.0));
}
