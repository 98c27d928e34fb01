#version 330 core
// One Jacobi iteration of equation 6, reading only the previous iterate (ping-pong).
// With FINAL the result leaves the working space as well (from_working_space, fused).
// Twin: jacobi_step (and from_working_space) in aarecovery/_reference.py.
#include "working.glsl"

uniform sampler2D model_map;
uniform sampler2D previous_iterate;
#if PURE_COLOURS
uniform sampler2D fixed_a_map;  // f of a thin feature's pure colour, where the model's code says so
uniform sampler2D fixed_b_map;
#endif

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
#if PURE_COLOURS
        int pure = code / 81;  // bit 0: extreme a is a fixed pure colour, bit 1: extreme b
        code -= 81 * pure;
#endif
        int a = code / 9;
        int b = code - 9 * a;
#if PURE_COLOURS
        vec4 at_a = (pure & 1) != 0 ? texelFetch(fixed_a_map, p, 0)
                                    : texelFetch(previous_iterate, clamp_to_image(p + OFFSETS[a], size), 0);
        vec4 at_b = (pure & 2) != 0 ? texelFetch(fixed_b_map, p, 0)
                                    : texelFetch(previous_iterate, clamp_to_image(p + OFFSETS[b], size), 0);
#else
        vec4 at_a = texelFetch(previous_iterate, clamp_to_image(p + OFFSETS[a], size), 0);
        vec4 at_b = texelFetch(previous_iterate, clamp_to_image(p + OFFSETS[b], size), 0);
#endif
        recovered = beta * (alpha * at_a + (1.0 - alpha) * at_b) + (1.0 - beta) * recovered;
    }
#if FINAL
    next_iterate = from_working(recovered, p);
#else
    next_iterate = recovered;
#endif
}
