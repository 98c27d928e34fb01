#version 430
// jacobi_step.frag on the compute path: a Jacobi iteration over the active blocks (jacobi.glsl
// does the work); with FINAL the result leaves the working space as well.
#include "compute.glsl"
#include "working.glsl"
#include "jacobi.glsl"
#if FINAL
#include "result_image.glsl"
#else
layout(rgba32f, binding = 0) uniform writeonly image2D next_iterate;
#endif

void main() {
    ivec2 p = block_origin() + ivec2(gl_LocalInvocationID.xy);
    if (!inside_image(p)) return;
    vec4 recovered = jacobi_step(p, image_size);
#if FINAL
    imageStore(result_image, p, result_texel(from_working(recovered, p)));
#else
    imageStore(next_iterate, p, recovered);
#endif
}
