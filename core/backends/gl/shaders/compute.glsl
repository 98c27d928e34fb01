// Which pixel a compute invocation computes. One 16 x 16 work group per block of pixels:
// with BLOCK_LIST, the blocks of a list that the classification built on the GPU
// (classify_blocks.comp, compact_blocks.comp), dispatched indirectly, so that the CPU never
// learns or waits for the count; without it, a grid of work groups over the whole image.
// Twin of blocks.vert on the fragment path.

#include "block_lists.glsl"

#define BLOCK_SIDE 16  // blocks.BLOCK_SIDE; a define, as GLSL 4.30 layouts take only literals
layout(local_size_x = BLOCK_SIDE, local_size_y = BLOCK_SIDE) in;

uniform ivec2 image_size;

#if BLOCK_LIST
layout(std430, binding = 0) readonly buffer BlockList { ivec2 block_list[]; };
// The lists' draw commands (block_lists.glsl): the instance count of list block_set is its length.
layout(std430, binding = 1) readonly buffer BlockCommands { uint block_commands[]; };
uniform int block_set;
#endif

// The block's first pixel; (-1, -1) for the work groups past the end of the list (a
// dispatch has at most 65535 groups a side, so long lists fill rows of groups).
ivec2 block_origin() {
#if BLOCK_LIST
    uint index = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    if (index >= block_commands[DRAW_COMMAND_WORDS * block_set + 1]) return ivec2(-1);
    return block_list[index] * BLOCK_SIDE;
#else
    return ivec2(gl_WorkGroupID.xy) * BLOCK_SIDE;
#endif
}

bool inside_image(ivec2 p) {
    return all(greaterThanEqual(p, ivec2(0))) && all(lessThan(p, image_size));
}
