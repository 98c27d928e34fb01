#version 430
// Step 2 of the block classification: append every block to its lists (block_lists.glsl)
// and count them into the indirect draw and dispatch commands. The order within a list
// does not matter: each pixel is written by exactly one invocation of a pass.
#include "block_lists.glsl"

layout(local_size_x = 64) in;

uniform ivec2 block_grid;
layout(std430, binding = 1) buffer BlockCommands { uint block_commands[]; };
layout(std430, binding = 2) readonly buffer BlockFlags { uint block_flags[]; };
layout(std430, binding = 3) writeonly buffer ActiveList { ivec2 active_list[]; };
layout(std430, binding = 4) writeonly buffer DilatedList { ivec2 dilated_list[]; };
layout(std430, binding = 5) writeonly buffer InactiveList { ivec2 inactive_list[]; };

uint append(int list) {
    return atomicAdd(block_commands[DRAW_COMMAND_WORDS * list + 1], 1u);
}

bool flagged(ivec2 block) {
    return all(greaterThanEqual(block, ivec2(0))) && all(lessThan(block, block_grid))
        && block_flags[block.y * block_grid.x + block.x] != 0u;
}

void main() {
    int index = int(gl_GlobalInvocationID.x);
    if (index >= block_grid.x * block_grid.y) return;
    ivec2 block = ivec2(index % block_grid.x, index / block_grid.x);
    bool flagged_here = block_flags[index] != 0u;
    if (flagged_here) active_list[append(LIST_ACTIVE)] = block;
    else inactive_list[append(LIST_INACTIVE)] = block;
    bool near = flagged_here;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) near = near || flagged(block + ivec2(dx, dy));
    if (near) dilated_list[append(LIST_DILATED)] = block;
}
