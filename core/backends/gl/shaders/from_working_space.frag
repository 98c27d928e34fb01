#version 330 core
// The last iterate (or F itself, for zero iterations) back to straight RGBA in the input
// encoding. Twin: from_working_space in aarecovery/spec/working_space.py.
#include "working.glsl"

uniform sampler2D recovered_work;

out vec4 result;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
#if FROM_FILTERED
    vec4 work = texelFetch(filtered_work, p, 0);
#else
    vec4 work = texelFetch(recovered_work, p, 0);
#endif
    result = from_working(work, p);
}
