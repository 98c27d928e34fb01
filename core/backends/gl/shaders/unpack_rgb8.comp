#version 430
// An 8-bit RGB image into an RGBA8 texture, from a buffer holding the caller's rows as they
// are (3 bytes a pixel, no padding). The compute path's upload of 8-bit RGB on a GPU: a
// driver turns RGB rows into its RGBA texels on the CPU, where this pass does it on the GPU
// (backend.py has the figures). Every byte k is stored as k / 255, which the RGBA8 format
// rounds back to k exactly; alpha is 1, as the RGB1 swizzle of a 3-channel texture reads.
#include "compute.glsl"

layout(std430, binding = 0) readonly buffer PackedRows { uint packed_words[]; };
layout(rgba8, binding = 0) uniform writeonly image2D unpacked_image;

uint packed_byte(uint index) {
    return (packed_words[index >> 2] >> ((index & 3u) * 8u)) & 255u;
}

void main() {
    ivec2 p = block_origin() + ivec2(gl_LocalInvocationID.xy);
    if (!inside_image(p)) return;
    uint first = 3u * (uint(p.y) * uint(image_size.x) + uint(p.x));
    vec3 rgb = vec3(packed_byte(first), packed_byte(first + 1u), packed_byte(first + 2u));
    imageStore(unpacked_image, p, vec4(rgb / 255.0, 1.0));
}
