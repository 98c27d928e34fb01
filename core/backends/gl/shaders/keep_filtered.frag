#version 330 core
// R = F where the recovery leaves F as it is: the blocks where the edge strength is 0, or
// everywhere for zero iterations. This is what from_working_space gives there (a pixel left
// at F keeps F bit for bit; aarecovery/spec/working_space.py), without its arithmetic.
// Where the result texture has F's own format, a copy of F replaces this pass.
#include "result_layout.glsl"

uniform sampler2D filtered_image;

out vec4 result;

void main() {
    result = result_texel(clamp(texelFetch(filtered_image, ivec2(gl_FragCoord.xy), 0), 0.0, 1.0));
}
