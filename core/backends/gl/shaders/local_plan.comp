#version 430
// local_plan.frag on the compute path.
#include "compute.glsl"
#include "colour.glsl"
#include "local_plan.glsl"

#if LOCAL_PASS == 3 && KEPT_INK
layout(rgba32f, binding = 0) uniform writeonly image2D value;  // the factor, the regions' weight, the kept ink
#elif LOCAL_PASS == 3
layout(rg32f, binding = 0) uniform writeonly image2D value;  // the factor and the regions' weight
#else
layout(r32f, binding = 0) uniform writeonly image2D value;
#endif

void main() {
    ivec2 p = block_origin() + ivec2(gl_LocalInvocationID.xy);
    if (!inside_image(p)) return;
    imageStore(value, p, vec4(local_plan(p, image_size), 1.0));
}
