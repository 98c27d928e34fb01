#version 430
// fit_blend_model.frag on the compute path, over the active blocks (blend_model.glsl does
// the work). With SHARED_TILE a work group first copies its block's O and F neighbourhoods
// (18 x 18 texels each) into shared memory, so that each texel is fetched once instead of
// up to nine times; which variant is faster depends on the device (see paths.py).
#include "compute.glsl"
#if SHARED_TILE
#define NEIGHBOURS_IN_SHARED_TILE 1
#endif
#include "working.glsl"

#if SHARED_TILE
const int TILE = BLOCK_SIDE + 2;
shared vec4 original_tile[TILE * TILE];
shared vec4 filtered_tile[TILE * TILE];
ivec2 tile_origin;  // the pixel in the tile's corner: the block's origin minus one

vec4 original_neighbour(ivec2 p, int i, ivec2 size) {
    ivec2 t = p + OFFSETS[i] - tile_origin;
    return original_tile[t.y * TILE + t.x];
}

vec4 filtered_neighbour(ivec2 p, int i, ivec2 size) {
    ivec2 t = p + OFFSETS[i] - tile_origin;
    return filtered_tile[t.y * TILE + t.x];
}
#endif

#include "sobel.glsl"
#if PURE_COLOURS
#include "pure_colours.glsl"
#endif
#include "blend_model.glsl"
#if LIVE_BLOCKS
#include "live_blocks.glsl"
#endif

layout(rgba32f, binding = 0) uniform writeonly image2D model;
layout(rgba32f, binding = 1) uniform writeonly image2D first_iterate;
#if MAPS
layout(r32f, binding = 2) uniform writeonly image2D edge_map;
#endif
#if JACOBI_CONSTANT
layout(rgba32f, binding = CONSTANT_LOCATION) uniform writeonly image2D jacobi_constant;
#endif

void main() {
    ivec2 origin = block_origin();
#if SHARED_TILE
    // The whole group takes part before the barrier, also past the image or the list.
    if (origin.x < 0) return;  // uniform across the group: the list ended
    tile_origin = origin - 1;
    for (int t = int(gl_LocalInvocationIndex); t < TILE * TILE; t += BLOCK_SIDE * BLOCK_SIDE) {
        ivec2 q = clamp_to_image(tile_origin + ivec2(t % TILE, t / TILE), image_size);
        original_tile[t] = texelFetch(original_work, q, 0);
        filtered_tile[t] = texelFetch(filtered_work, q, 0);
    }
    barrier();
#endif
    ivec2 p = origin + ivec2(gl_LocalInvocationID.xy);
    if (!inside_image(p)) return;
    BlendFit fit = fit_blend_model(p, image_size);
    imageStore(model, p, fit.model);
    imageStore(first_iterate, p, fit.first_iterate);
#if LIVE_BLOCKS
    flag_live(p, fit, image_size);
#endif
#if MAPS
    imageStore(edge_map, p, vec4(fit.edge, 0.0, 0.0, 1.0));
#endif
#if JACOBI_CONSTANT
    imageStore(jacobi_constant, p, fit.jacobi_constant);
#endif
}
