#version 430
// Step 3 of the block classification: the dispatch commands from the lists' lengths, in
// rows of at most MAX_GROUPS work groups (65535, the least every GL 4.3 device allows a side;
// the tests make it small).
#include "block_lists.glsl"

layout(local_size_x = 1) in;

layout(std430, binding = 1) buffer BlockCommands { uint block_commands[]; };

void main() {
    for (int list = 0; list < LIST_COUNT; ++list) {
        uint length = block_commands[DRAW_COMMAND_WORDS * list + 1];
        int dispatch = DRAW_COMMAND_WORDS * LIST_COUNT + DISPATCH_COMMAND_WORDS * list;
        block_commands[dispatch] = min(length, uint(MAX_GROUPS));
        block_commands[dispatch + 1] = (length + uint(MAX_GROUPS) - 1u) / uint(MAX_GROUPS);
        block_commands[dispatch + 2] = 1u;
    }
}
