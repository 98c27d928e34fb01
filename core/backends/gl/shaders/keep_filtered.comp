#version 430
// keep_filtered.frag on the compute path: R = F where the recovery leaves F as it is.
#include "compute.glsl"
#include "result_image.glsl"

uniform sampler2D filtered_image;

void main() {
    ivec2 p = block_origin() + ivec2(gl_LocalInvocationID.xy);
    if (!inside_image(p)) return;
    imageStore(result_image, p, result_texel(clamp(texelFetch(filtered_image, p, 0), 0.0, 1.0)));
}
