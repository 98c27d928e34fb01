#version 430
// The pure colours' blocks (twin: pure_colour_mask in backends/gl/blocks.py): of O's active
// blocks, FIT_WHOLE those with a ridge's wake (pure_colour_blocks.glsl) on their pixels or
// within MARGIN of their sides in O's active blocks, and with PURE_GATE the gate of drawn
// content open on one of their own pixels; FIT_PLAIN the others with any wake that near
// (flag_pure_colour_blocks.frag wrote every pixel of O's active blocks; elsewhere the
// texture holds what an earlier pass left). One invocation per block; the scan ends at the
// first ridge's wake, so a block with thin features costs a few gathers and one without 100.
layout(local_size_x = 64) in;

#ifndef PURE_GATE
#define PURE_GATE 0
#endif

uniform sampler2D wakes;
#if PURE_GATE
uniform sampler2D strength_factor;  // the local plan's regions' weight in .g (local_plan.glsl)
#endif
uniform ivec2 image_size;
uniform ivec2 block_grid;  // blocks across and down
layout(std430, binding = 2) writeonly buffer BlockFlags { uint block_flags[]; };
layout(std430, binding = 7) readonly buffer OriginalFlags { uint original_flags[]; };  // O's classification

const int BLOCK_SIDE = 16;
const int MARGIN = 2;
const uint WAKE_RIDGE = 2u;  // pure_colour_blocks.glsl
const uint FIT_PLAIN = 1u;
const uint FIT_WHOLE = 2u;

bool original_active(ivec2 block) {
    return all(greaterThanEqual(block, ivec2(0))) && all(lessThan(block, block_grid))
           && original_flags[block.y * block_grid.x + block.x] != 0u;
}

void main() {
    int index = int(gl_GlobalInvocationID.x);
    if (index >= block_grid.x * block_grid.y) return;
    ivec2 block = ivec2(index % block_grid.x, index / block_grid.x);
    // O's active blocks among this one and its 8 neighbours, bit (dy + 1) * 3 + dx + 1.
    uint around = 0u;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
            if (original_active(block + ivec2(dx, dy))) around |= 1u << uint((dy + 1) * 3 + dx + 1);
    uint found = 0u;
    if ((around & 16u) != 0u) {
        ivec2 low = max(block * BLOCK_SIDE - MARGIN, ivec2(0));
        ivec2 high = min(block * BLOCK_SIDE + BLOCK_SIDE - 1 + MARGIN, image_size - 1);
        // 2 x 2 texels a gather, rows then columns, left as soon as every lane of a group has
        // found a ridge's wake. The region starts on an even texel (MARGIN and a block's side are even),
        // so a gather never straddles two blocks; past the image's last texel the texture's
        // clamped edge repeats it. A flat index took a division and a remainder per texel,
        // which llvmpipe does lane by lane (thin-features pair at 4096^2, pass clock: 0.11-0.13 ->
        // 0.05-0.06 s, the same lists).
        vec2 texel = 1.0 / vec2(image_size);
        for (int y = low.y; y <= high.y && (found & WAKE_RIDGE) == 0u; y += 2) {
            uint row_bits = around >> uint((y / BLOCK_SIDE - block.y + 1) * 3);
            for (int x = low.x; x <= high.x && (found & WAKE_RIDGE) == 0u; x += 2) {
                if (((row_bits >> uint(x / BLOCK_SIDE - block.x + 1)) & 1u) != 0u) {
                    uvec4 quad = uvec4(textureGather(wakes, vec2(x + 1, y + 1) * texel) * 255.0 + 0.5);
                    found |= quad.x | quad.y | quad.z | quad.w;
                }
            }
        }
    }
    bool whole = (found & WAKE_RIDGE) != 0u;
#if PURE_GATE
    // Only a pixel whose gate is open extends its extremes.
    ivec2 first = block * BLOCK_SIDE;
    ivec2 last = min(first + BLOCK_SIDE - 1, image_size - 1);
    int across_block = last.x - first.x + 1;
    int pixels = whole ? across_block * (last.y - first.y + 1) : 0;
    bool open = false;
    for (int i = 0; i < pixels && !open; ++i)
        open = texelFetch(strength_factor, first + ivec2(i % across_block, i / across_block), 0).g > 0.0;
    whole = whole && open;
#endif
    block_flags[index] = whole ? FIT_WHOLE : (found != 0u ? FIT_PLAIN : 0u);
}
