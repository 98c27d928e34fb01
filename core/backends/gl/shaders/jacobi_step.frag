#version 330 core
// A Jacobi iteration as a fragment pass (jacobi.glsl does the work); with FINAL the result
// leaves the working space as well (from_working_space, fused).
#include "working.glsl"
#include "jacobi.glsl"
#include "result_layout.glsl"

out vec4 next_iterate;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 recovered = jacobi_step(p, textureSize(filtered_work, 0));
#if FINAL
    next_iterate = result_texel(from_working(recovered, p));
#else
    next_iterate = recovered;
#endif
}
