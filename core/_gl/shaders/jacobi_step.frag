#version 330 core
// One Jacobi iteration of equation 6, reading only the previous iterate (ping-pong).
// With FINAL the result leaves the working space as well (from_working_space, fused).
// Twin: jacobi_step (and from_working_space) in aarecovery/_reference.py.
#include "working.glsl"

uniform sampler2D model_map;
uniform sampler2D previous_iterate;

out vec4 next_iterate;

void main() {
    ivec2 size = textureSize(filtered_work, 0);
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 model = texelFetch(model_map, p, 0);
    float alpha = model.x;
    float beta = model.y;
    vec4 recovered = texelFetch(filtered_work, p, 0);
    // Most pixels are not edges (beta = 0): they keep F without gathering R.
    if (beta != 0.0) {
        int code = int(model.z + 0.5);
        int a = code / 9;
        int b = code - 9 * a;
        vec4 at_a = texelFetch(previous_iterate, clamp_to_image(p + OFFSETS[a], size), 0);
        vec4 at_b = texelFetch(previous_iterate, clamp_to_image(p + OFFSETS[b], size), 0);
        recovered = beta * (alpha * at_a + (1.0 - alpha) * at_b) + (1.0 - beta) * recovered;
    }
#if FINAL
    next_iterate = from_working(recovered, p);
#else
    next_iterate = recovered;
#endif
}
