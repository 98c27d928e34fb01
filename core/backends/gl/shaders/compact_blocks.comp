#version 430
// Step 2 of the block classification: append every block to its lists (block_lists.glsl)
// and count them into the indirect draw and dispatch commands. The order within a list
// does not matter: each pixel is written by exactly one invocation of a pass.
//
// With RUNS (the fragment path) a list holds runs of blocks along a row instead, one entry
// per run, (column | (length - 1) << 16, row): llvmpipe sets up every triangle on the CPU,
// and a quad per block made the passes 1.5x slower where most blocks are active.
#include "block_lists.glsl"

layout(local_size_x = 64) in;

uniform ivec2 block_grid;
layout(std430, binding = 1) buffer BlockCommands { uint block_commands[]; };
layout(std430, binding = 2) readonly buffer BlockFlags { uint block_flags[]; };
layout(std430, binding = 3) writeonly buffer ActiveList { ivec2 active_list[]; };
layout(std430, binding = 4) writeonly buffer DilatedList { ivec2 dilated_list[]; };
layout(std430, binding = 5) writeonly buffer InactiveList { ivec2 inactive_list[]; };

bool inside(ivec2 block) {
    return all(greaterThanEqual(block, ivec2(0))) && all(lessThan(block, block_grid));
}

// A block is flagged when its flags hold a bit of want_bits (every classification but the
// pure colours' split of their blocks wants any).
uniform uint want_bits;

bool flagged(ivec2 block) {
    return inside(block) && (block_flags[block.y * block_grid.x + block.x] & want_bits) != 0u;
}

bool member(int list, ivec2 block) {
    if (!inside(block)) return false;
    if (list == LIST_ACTIVE) return flagged(block);
    if (list == LIST_INACTIVE) return !flagged(block);
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
            if (flagged(block + ivec2(dx, dy))) return true;
    return false;
}

void append(int list, ivec2 block) {
#if RUNS
    if (member(list, block - ivec2(1, 0))) return;  // inside a run that starts further left
    int length = 1;
    while (member(list, block + ivec2(length, 0))) ++length;
    ivec2 entry = ivec2(block.x | ((length - 1) << 16), block.y);
#else
    ivec2 entry = block;
#endif
    uint index = atomicAdd(block_commands[DRAW_COMMAND_WORDS * list + 1], 1u);
#if RUNS
    atomicAdd(block_commands[BLOCK_COUNTS + list], uint(length));
#else
    atomicAdd(block_commands[BLOCK_COUNTS + list], 1u);
#endif
    if (list == LIST_ACTIVE) active_list[index] = entry;
    else if (list == LIST_DILATED) dilated_list[index] = entry;
    else inactive_list[index] = entry;
}

void main() {
    int index = int(gl_GlobalInvocationID.x);
    if (index >= block_grid.x * block_grid.y) return;
    ivec2 block = ivec2(index % block_grid.x, index / block_grid.x);
    for (int list = 0; list < LIST_COUNT; ++list)
        if (member(list, block)) append(list, block);
}
