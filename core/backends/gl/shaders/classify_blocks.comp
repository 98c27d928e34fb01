#version 430
// Step 1 of the block classification on the GPU: flag every 16 x 16 block that a pixel
// differing from a 4-neighbour lies in or within MARGIN pixels of (twin: active_mask in
// backends/gl/blocks.py, which says why the margin is 2). Values are compared as uploaded:
// equal there means equal in the working space.
//
// An invocation walks one column of one block (16 pixels, adjacent invocations in adjacent
// columns), comparing each pixel with its right and lower neighbours: two fetches a pixel,
// and the flags of the blocks around it written once, from the rows where it found a
// difference (the rows lie in one block, so their extent is exact).
#include "block_lists.glsl"

layout(local_size_x = 16, local_size_y = 16) in;  // 16 columns of 16 blocks down

uniform sampler2D image;  // O or F as uploaded
uniform ivec2 image_size;
uniform ivec2 block_grid;  // blocks across and down
layout(std430, binding = 2) buffer BlockFlags { uint block_flags[]; };

const int BLOCK_SIDE = 16;
const int MARGIN = 2;

// Flag the blocks within MARGIN of the pixels from `low` to `high`.
void flag_around(ivec2 low, ivec2 high) {
    ivec2 first = max(low - MARGIN, ivec2(0)) / BLOCK_SIDE;
    ivec2 last = min((high + MARGIN) / BLOCK_SIDE, block_grid - 1);
    for (int y = first.y; y <= last.y; ++y) {
        for (int x = first.x; x <= last.x; ++x) {
            int index = y * block_grid.x + x;
            // Every writer stores the same 1; reading first spares most of the writes.
            if (block_flags[index] == 0u) block_flags[index] = 1u;
        }
    }
}

void main() {
    int x = int(gl_GlobalInvocationID.x);
    int top = int(gl_GlobalInvocationID.y) * BLOCK_SIDE;
    if (x >= image_size.x || top >= image_size.y) return;
    int bottom = min(top + BLOCK_SIDE, image_size.y) - 1;
    bool has_right = x + 1 < image_size.x;
    // Rows of the differing pairs: with the right neighbour (pixels x and x + 1), and with
    // the lower neighbour (rows y and y + 1).
    int across_low = image_size.y, across_high = -1, down_low = image_size.y, down_high = -1;
    vec4 here = texelFetch(image, ivec2(x, top), 0);
    for (int y = top; y <= bottom; ++y) {
        if (has_right && any(notEqual(here, texelFetch(image, ivec2(x + 1, y), 0)))) {
            across_low = min(across_low, y);
            across_high = y;
        }
        vec4 below = here;
        if (y + 1 < image_size.y) {
            below = texelFetch(image, ivec2(x, y + 1), 0);
            if (any(notEqual(here, below))) {
                down_low = min(down_low, y);
                down_high = y + 1;
            }
        }
        here = below;
    }
    if (across_high >= 0) flag_around(ivec2(x, across_low), ivec2(x + 1, across_high));
    if (down_high >= 0) flag_around(ivec2(x, down_low), ivec2(x, down_high));
}
