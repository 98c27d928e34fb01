#version 330 core
// One instance per run of blocks along a row (compact_blocks.comp with RUNS): two triangles
// covering it, clipped to the image. The passes draw only the blocks their lists hold;
// llvmpipe shades every fragment a triangle covers (it runs both sides of a branch), so
// skipping must happen here.
in ivec2 block;  // (column | (run length - 1) << 16, row)
uniform ivec2 image_size;
uniform int block_side;

const ivec2 CORNERS[6] = ivec2[6](ivec2(0, 0), ivec2(1, 0), ivec2(0, 1), ivec2(0, 1), ivec2(1, 0), ivec2(1, 1));

void main() {
    ivec2 origin = ivec2(block.x & 0xFFFF, block.y);
    ivec2 extent = ivec2((block.x >> 16) + 1, 1);
    vec2 pixel = vec2(min((origin + CORNERS[gl_VertexID] * extent) * block_side, image_size));
    gl_Position = vec4(pixel / vec2(image_size) * 2.0 - 1.0, 0.0, 1.0);
}
