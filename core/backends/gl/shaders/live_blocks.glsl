// The blocks the Jacobi steps must cover, flagged by the fit (twin: live_mask in
// backends/gl/blocks.py): where a step can give other than F (BlendFit.live), and, where it
// gathers (beta != 0), the blocks of the two texels it gathers, so that every value a
// listed pixel reads was written by the step before. A step at any other pixel gives
// exactly F, which the result already holds, so its block is skipped: with pure colours the
// fit covers O's active blocks, about twice F's, and few of O's blocks outside F's change.
// Needs neighbourhood.glsl first; the flags are compacted into lists by compact_blocks.comp.
layout(std430, binding = 6) buffer LiveFlags { uint live_flags[]; };
uniform int live_columns;  // blocks across the image
const int LIVE_BLOCK_SIDE = 16;  // blocks.BLOCK_SIDE

void flag_live_block(ivec2 q) {
    int index = (q.y / LIVE_BLOCK_SIDE) * live_columns + q.x / LIVE_BLOCK_SIDE;
    // Every writer stores the same 1; reading first spares most of the writes.
    if (live_flags[index] == 0u) live_flags[index] = 1u;
}

void flag_live(ivec2 p, BlendFit fit, ivec2 size) {
    if (!fit.live) return;
    flag_live_block(p);
    if (fit.model.y != 0.0) {
        vec4 offsets = extreme_offsets(extremes_code(fit.model.z));
        flag_live_block(clamp_to_image(p + ivec2(offsets.xy), size));
        flag_live_block(clamp_to_image(p + ivec2(offsets.zw), size));
    }
}
