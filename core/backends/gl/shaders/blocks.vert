#version 330 core
// One instance per block of pixels: two triangles covering it, clipped to the image.
// The passes draw only the blocks where F is not flat; llvmpipe shades every fragment a
// triangle covers (it runs both sides of a branch), so skipping must happen here.
in ivec2 block;
uniform ivec2 image_size;
uniform int block_side;

const ivec2 CORNERS[6] = ivec2[6](ivec2(0, 0), ivec2(1, 0), ivec2(0, 1), ivec2(0, 1), ivec2(1, 0), ivec2(1, 1));

void main() {
    vec2 pixel = vec2(min((block + CORNERS[gl_VertexID]) * block_side, image_size));
    gl_Position = vec4(pixel / vec2(image_size) * 2.0 - 1.0, 0.0, 1.0);
}
