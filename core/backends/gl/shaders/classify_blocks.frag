#version 330 core
// The block classification where there are no compute shaders (GL 3.3 to 4.2, macOS): one
// fragment per block of a target the size of the block grid, 1 where a pixel in the block
// or within MARGIN of it differs from a 4-neighbour (twin: active_mask in blocks.py). The
// CPU makes the lists from this mask, 1/256 of the image.
uniform sampler2D image;  // O or F as uploaded

const int BLOCK_SIDE = 16;
const int MARGIN = 2;

out vec4 flag;

bool differs(vec4 value, ivec2 q, ivec2 size) {
    return all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, size))
        && any(notEqual(value, texelFetch(image, q, 0)));
}

void main() {
    ivec2 size = textureSize(image, 0);
    ivec2 block = ivec2(gl_FragCoord.xy);
    ivec2 low = max(block * BLOCK_SIDE - MARGIN, ivec2(0));
    ivec2 high = min(block * BLOCK_SIDE + (BLOCK_SIDE - 1 + MARGIN), size - 1);
    bool differing = false;
    for (int y = low.y; y <= high.y && !differing; ++y) {
        for (int x = low.x; x <= high.x && !differing; ++x) {
            ivec2 p = ivec2(x, y);
            vec4 value = texelFetch(image, p, 0);
            differing = differs(value, p + ivec2(1, 0), size) || differs(value, p + ivec2(0, 1), size)
                  || differs(value, p - ivec2(1, 0), size) || differs(value, p - ivec2(0, 1), size);
        }
    }
    flag = vec4(differing ? 1.0 : 0.0);
}
