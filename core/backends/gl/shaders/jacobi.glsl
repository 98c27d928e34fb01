// One Jacobi iteration of equation 6 at one pixel, reading only the previous iterate
// (ping-pong). Twin: jacobi_step in aarecovery/spec/jacobi.py. Needs working.glsl first.

uniform sampler2D model_map;
uniform sampler2D previous_iterate;
#if JACOBI_CONSTANT
// (1 - beta) F plus beta's share of the fixed pure colours (and, towards O, (1 - beta - g) F
// plus g O), written by the fit (blend_model.glsl): what each step adds to the gathers of R.
// It stands in for F, so the step reads as many texels as the paper's (model, constant, two
// gathers) instead of fetching both fixed colours at every pixel (llvmpipe fetches both
// sides of a ?:).
uniform sampler2D jacobi_constant_map;
#endif

vec4 jacobi_step(ivec2 p, ivec2 size) {
    vec4 model = texelFetch(model_map, p, 0);
    float alpha = model.x;
    float beta = model.y;
#if JACOBI_CONSTANT
    vec4 recovered = texelFetch(jacobi_constant_map, p, 0);  // exactly F where beta and g are 0
#else
    vec4 recovered = texelFetch(filtered_work, p, 0);
#endif
    // Most pixels are not edges (beta = 0): they keep F without gathering R.
    if (beta != 0.0) {
        // The extremes' offsets, two base-3 digits each (see blend_model.glsl).
        float code = model.z;
#if PURE_COLOURS
        float pure = floor((code + 0.5) * (1.0 / 81.0));  // 1: extreme a is a fixed pure colour, 2: b, 3: both
        code -= 81.0 * pure;
#endif
        vec4 offsets = extreme_offsets(code);  // a.x, a.y, b.x, b.y in -1..1
        vec4 at_a = texelFetch(previous_iterate, clamp_to_image(p + ivec2(offsets.xy), size), 0);
        vec4 at_b = texelFetch(previous_iterate, clamp_to_image(p + ivec2(offsets.zw), size), 0);
#if PURE_COLOURS
        // A fixed extreme's share is in the constant: its gather gets no weight.
        float weight_a = (pure == 1.0 || pure == 3.0) ? 0.0 : beta * alpha;
        float weight_b = pure >= 2.0 ? 0.0 : beta * (1.0 - alpha);
        recovered = weight_a * at_a + weight_b * at_b + recovered;
#elif JACOBI_CONSTANT
        recovered = beta * (alpha * at_a + (1.0 - alpha) * at_b) + recovered;
#else
        recovered = beta * (alpha * at_a + (1.0 - alpha) * at_b) + (1.0 - beta) * recovered;
#endif
    }
    return recovered;
}
