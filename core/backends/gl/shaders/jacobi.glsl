// One Jacobi iteration of equation 6 at one pixel, reading only the previous iterate
// (ping-pong). Twin: jacobi_step in aarecovery/spec/jacobi.py. Needs working.glsl first.

uniform sampler2D model_map;
uniform sampler2D previous_iterate;
#if PURE_COLOURS
uniform sampler2D fixed_a_map;  // f of a thin feature's pure colour, where the model's code says so
uniform sampler2D fixed_b_map;
#endif

vec4 jacobi_step(ivec2 p, ivec2 size) {
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
    return recovered;
}
