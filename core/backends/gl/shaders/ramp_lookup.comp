#version 430
// ramp_lookup.frag on the compute path: the ramp lookup over F's active blocks after the
// Jacobi steps, stored where a pixel takes it.
#include "compute.glsl"
#include "working.glsl"
#include "jacobi.glsl"
#include "result_image.glsl"
#include "ramp_lookup.glsl"

void main() {
    ivec2 p = block_origin() + ivec2(gl_LocalInvocationID.xy);
    if (!inside_image(p) || !filtered_varies(p, image_size)) return;
    vec3 delta = ramp_delta(p, image_size);
    if (all(equal(delta, vec3(0.0)))) return;
    vec4 straight = from_working(jacobi_step(p, image_size), p);
    imageStore(result_image, p, result_texel(ramp_added(straight, delta, texelFetch(model_map, p, 0).y)));
}
