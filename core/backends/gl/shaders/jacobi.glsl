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
        // The extremes' offsets, two base-3 digits each (see blend_model.glsl), decoded in
        // float arithmetic: integer division and indexing an array by a variable are
        // scalar code on a CPU's vector units (llvmpipe).
        float code = model.z;
#if PURE_COLOURS
        float pure = floor((code + 0.5) * (1.0 / 81.0));  // 1: extreme a is a fixed pure colour, 2: b, 3: both
        code -= 81.0 * pure;
#endif
        vec4 digits = floor((code + 0.5) / vec4(1.0, 3.0, 9.0, 27.0));
        vec4 offsets = digits - 3.0 * floor(digits * (1.0 / 3.0)) - 1.0;  // a.x, a.y, b.x, b.y in -1..1
        ivec2 at_a_position = clamp_to_image(p + ivec2(offsets.xy), size);
        ivec2 at_b_position = clamp_to_image(p + ivec2(offsets.zw), size);
#if PURE_COLOURS
        vec4 at_a = (pure == 1.0 || pure == 3.0) ? texelFetch(fixed_a_map, p, 0)
                                                 : texelFetch(previous_iterate, at_a_position, 0);
        vec4 at_b = pure >= 2.0 ? texelFetch(fixed_b_map, p, 0) : texelFetch(previous_iterate, at_b_position, 0);
#else
        vec4 at_a = texelFetch(previous_iterate, at_a_position, 0);
        vec4 at_b = texelFetch(previous_iterate, at_b_position, 0);
#endif
        recovered = beta * (alpha * at_a + (1.0 - alpha) * at_b) + (1.0 - beta) * recovered;
    }
    return recovered;
}
