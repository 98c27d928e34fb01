#version 430
// to_working_space.frag on the compute path: O and F into the working space, over the
// blocks that the passes read (the active blocks and those around them).
// Twin: to_working_space in aarecovery/spec/working_space.py.
#include "compute.glsl"
#include "colour.glsl"

uniform sampler2D original_image;
uniform sampler2D filtered_image;
layout(rgba32f, binding = 0) uniform writeonly image2D original_work;
layout(rgba32f, binding = 1) uniform writeonly image2D filtered_work;

void main() {
    ivec2 p = block_origin() + ivec2(gl_LocalInvocationID.xy);
    if (!inside_image(p)) return;
    imageStore(original_work, p, to_working(texelFetch(original_image, p, 0), INPUT_CONVERT));
    imageStore(filtered_work, p, to_working(texelFetch(filtered_image, p, 0), INPUT_CONVERT));
}
