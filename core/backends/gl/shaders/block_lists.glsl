// The three block lists of a classified image and their indirect commands, in one buffer:
// first a draw command per list (DrawArraysIndirectCommand: vertex count, instance count,
// first vertex, base instance; padded to the 5 words moderngl's stride assumes), then a
// dispatch command per list (DispatchIndirectCommand: groups x, y, z), then the number of
// blocks per list (more than the entries where they are runs). blocks.py mirrors the layout
// for the CPU (LISTS, DRAW_COMMAND_WORDS, DISPATCH_COMMAND_WORDS).
const int DRAW_COMMAND_WORDS = 5;
const int DISPATCH_COMMAND_WORDS = 3;
const int LIST_ACTIVE = 0;    // blocks where the edge strength can be non-zero
const int LIST_DILATED = 1;   // those and the blocks around them: what the active blocks read
const int LIST_INACTIVE = 2;  // the rest, where R = F
const int LIST_COUNT = 3;
const int BLOCK_COUNTS = (DRAW_COMMAND_WORDS + DISPATCH_COMMAND_WORDS) * LIST_COUNT;  // first word of the counts
