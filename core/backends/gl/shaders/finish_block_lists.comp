#version 430
// Step 3 of the block classification: the dispatch commands from the lists' lengths, in
// rows of at most MAX_GROUPS work groups (65535, the least every GL 4.3 device allows a side;
// the tests make it small). A list longer than a row is spread evenly over the fewest rows,
// so that the groups past its end are fewer than the rows: 65,536 blocks (a 4096 x 4096
// image) dispatched as 65,535 x 2 launched 131,070 groups, and every pass ran 1.6-3.7 times
// slower on an NVIDIA H100 than at 4096 x 4080 (65,280 blocks, one row).
#include "block_lists.glsl"

layout(local_size_x = 1) in;

layout(std430, binding = 1) buffer BlockCommands { uint block_commands[]; };

void main() {
    for (int list = 0; list < LIST_COUNT; ++list) {
        uint length = block_commands[DRAW_COMMAND_WORDS * list + 1];
        int dispatch = DRAW_COMMAND_WORDS * LIST_COUNT + DISPATCH_COMMAND_WORDS * list;
        uint rows = max((length + uint(MAX_GROUPS) - 1u) / uint(MAX_GROUPS), 1u);
        block_commands[dispatch] = (length + rows - 1u) / rows;
        block_commands[dispatch + 1] = length == 0u ? 0u : rows;
        block_commands[dispatch + 2] = 1u;
    }
}
