#version 430
// local_plan.frag on the compute path.
#include "compute.glsl"
#include "colour.glsl"
#include "local_plan.glsl"

layout(r32f, binding = 0) uniform writeonly image2D value;

void main() {
    ivec2 p = block_origin() + ivec2(gl_LocalInvocationID.xy);
    if (!inside_image(p)) return;
    imageStore(value, p, vec4(local_plan(p, image_size), 0.0, 0.0, 1.0));
}
