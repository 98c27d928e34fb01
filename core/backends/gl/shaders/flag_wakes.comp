#version 430
// The pure colours' blocks (twin: pure_colour_mask in backends/gl/blocks.py): each of O's
// active blocks whose pixels, or those within MARGIN of its sides in O's active blocks,
// hold a wake (flag_pure_colour_blocks.frag, which wrote every pixel of O's active blocks
// and nothing elsewhere that is read here). One invocation per block; the scan ends at the
// first wake, so a block with edges of F costs a few fetches and one without 400.
layout(local_size_x = 64) in;

uniform sampler2D wakes;
uniform ivec2 image_size;
uniform ivec2 block_grid;  // blocks across and down
layout(std430, binding = 2) writeonly buffer BlockFlags { uint block_flags[]; };
layout(std430, binding = 7) readonly buffer OriginalFlags { uint original_flags[]; };  // O's classification

const int BLOCK_SIDE = 16;
const int MARGIN = 2;

bool original_active(ivec2 block) {
    return all(greaterThanEqual(block, ivec2(0))) && all(lessThan(block, block_grid))
           && original_flags[block.y * block_grid.x + block.x] != 0u;
}

void main() {
    int index = int(gl_GlobalInvocationID.x);
    if (index >= block_grid.x * block_grid.y) return;
    ivec2 block = ivec2(index % block_grid.x, index / block_grid.x);
    // O's active blocks among this one and its 8 neighbours, bit (dy + 1) * 3 + dx + 1:
    // a wake counts only in those (elsewhere the texture holds what an earlier pass left).
    uint around = 0u;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
            if (original_active(block + ivec2(dx, dy))) around |= 1u << uint((dy + 1) * 3 + dx + 1);
    bool found = false;
    if ((around & 16u) != 0u) {
        ivec2 low = max(block * BLOCK_SIDE - MARGIN, ivec2(0));
        ivec2 high = min(block * BLOCK_SIDE + BLOCK_SIDE - 1 + MARGIN, image_size - 1);
        int across = high.x - low.x + 1;
        int count = across * (high.y - low.y + 1);
        // One loop, left as soon as every lane of a group has found a wake.
        for (int i = 0; i < count && !found; ++i) {
            ivec2 q = low + ivec2(i % across, i / across);
            ivec2 at = q / BLOCK_SIDE - block + 1;
            found = ((around >> uint(at.y * 3 + at.x)) & 1u) != 0u && texelFetch(wakes, q, 0).r > 0.0;
        }
    }
    block_flags[index] = found ? 1u : 0u;
}
