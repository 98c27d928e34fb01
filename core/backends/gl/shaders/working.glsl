// The working space (premultiplied RGBA, colour in the blend space) and the way back.
// Twin of to_working_space / from_working_space in aarecovery/spec/working_space.py.
// The backend defines OUTPUT_CONVERT (blend space -> input encoding) as a CONVERT_* mode.
#include "colour.glsl"
#include "neighbourhood.glsl"

uniform sampler2D original_work;
uniform sampler2D filtered_work;
uniform sampler2D filtered_image;  // F as given, for the colour of fully transparent pixels

// Neighbour i (OFFSETS order) of pixel p in the working space. A compute pass that keeps its
// block's neighbourhood in shared memory defines NEIGHBOURS_IN_SHARED_TILE and its own pair.
#ifndef NEIGHBOURS_IN_SHARED_TILE
vec4 original_neighbour(ivec2 p, int i, ivec2 size) {
    return texelFetch(original_work, clamp_to_image(p + OFFSETS[i], size), 0);
}

vec4 filtered_neighbour(ivec2 p, int i, ivec2 size) {
    return texelFetch(filtered_work, clamp_to_image(p + OFFSETS[i], size), 0);
}
#endif

// Whether F as uploaded differs from one of p's four neighbours (equal there is equal in the
// working space): where the ramp lookup acts, and what wakes the pure colours' fit.
bool filtered_varies(ivec2 p, ivec2 size) {
    vec4 centre = texelFetch(filtered_image, p, 0);
    return any(notEqual(texelFetch(filtered_image, clamp_to_image(p + ivec2(0, -1), size), 0), centre))
        || any(notEqual(texelFetch(filtered_image, clamp_to_image(p + ivec2(-1, 0), size), 0), centre))
        || any(notEqual(texelFetch(filtered_image, clamp_to_image(p + ivec2(1, 0), size), 0), centre))
        || any(notEqual(texelFetch(filtered_image, clamp_to_image(p + ivec2(0, 1), size), 0), centre));
}

// A result's coverage at or below this is none (twin: VISIBLE_COVERAGE in working_space.py,
// which says why).
const float VISIBLE_COVERAGE = 0.5 / 65535.0;

// Straight RGBA in the input encoding; a transparent result keeps F's colour, and a
// pixel the recovery left exactly at F keeps F bit for bit (decode + encode is not exact).
vec4 from_working(vec4 work, ivec2 p) {
#if EXACT_UNTOUCHED
    // 8-bit results round the tiny decode/encode error away, so only deeper ones need this.
    if (work == texelFetch(filtered_work, p, 0)) return clamp(texelFetch(filtered_image, p, 0), 0.0, 1.0);
#endif
    float coverage = clamp(work.a, 0.0, 1.0);
    if (coverage > VISIBLE_COVERAGE) {
        vec3 colour = clamp(work.rgb / coverage, 0.0, 1.0);
        return vec4(convert_colour(colour, OUTPUT_CONVERT), coverage);
    }
    return vec4(clamp(texelFetch(filtered_image, p, 0).rgb, 0.0, 1.0), 0.0);
}
